// Bispectral (re-radiation) channels of the spectral EXR: T.<λin>nm.<λout>nm, the layout of the
// reference library (Fichet, Pacanowski, Wilkie, JCGT 2021: excitation wavelength first, then the
// re-radiation wavelength), one set per light layer. docs/spectral-exr.md, "Bispectral channels".
#include "prizma/spectral/bispectral.h"

#include <ImfChannelList.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "bispectral_exr.h"
#include "exr/checksum.h"
#include "prizma/spectral/error.h"
#include "text_util.h"

namespace prizma::spectral {
namespace {

constexpr double kSpeedOfLight_m_per_s = 299792458.0;
constexpr float kHalfMax = 65504.0f;

double unit_factor(const std::string& prefix) {
  static const std::map<std::string, double> kFactors = {
      {"Y", 1e24}, {"Z", 1e21}, {"E", 1e18}, {"P", 1e15}, {"T", 1e12}, {"G", 1e9},  {"M", 1e6},  {"k", 1e3},
      {"h", 1e2},  {"da", 1e1}, {"", 1.0},   {"d", 1e-1}, {"c", 1e-2}, {"m", 1e-3}, {"u", 1e-6}, {"n", 1e-9},
      {"p", 1e-12}};
  return kFactors.at(prefix);
}

double to_nm(const std::string& name, std::string number, const std::string& prefix, const std::string& unit,
             const std::string& path) {
  const std::string shown = number;
  std::replace(number.begin(), number.end(), ',', '.');
  double value = 0.0;
  if (!detail::parse_double(number, value) || !std::isfinite(value) || value <= 0.0)
    throw InputError(path, "channel \"" + name + "\": \"" + shown + "\" is not a positive wavelength");
  value *= unit_factor(prefix);
  const double nm = unit == "Hz" ? kSpeedOfLight_m_per_s / value * 1e9 : value * 1e9;
  if (!std::isfinite(nm) || nm <= 0.0) throw InputError(path, "channel \"" + name + "\": wavelength out of range");
  return nm;
}

std::uint64_t hash_values(const float* v, std::size_t n) { return exr::layer_hash(exr::LayerKind::Bispectral, v, n); }

std::string pair_text(const SpectralImage& image, const BinPair& pr) {
  std::ostringstream os;
  os << "bins (in " << pr.in << ", out " << pr.out << ")";
  if (pr.in >= 0 && pr.in < image.bins.size() && pr.out >= 0 && pr.out < image.bins.size())
    os << " = " << image.bins.centre_nm(pr.in) << " nm → " << image.bins.centre_nm(pr.out) << " nm";
  return os.str();
}

}  // namespace

std::string reradiation_channel_name(double in_nm, double out_nm, std::string_view layer) {
  // spectral_channel_name gives "<layer>.T.<in>nm"; the out wavelength follows without its "T.".
  return spectral_channel_name(in_nm, layer) + "." + spectral_channel_name(out_nm).substr(2);
}

void check_reradiation_layout(const SpectralImage& image, const std::string& input) {
  const int n = image.bins.size();
  for (std::size_t k = 0; k < image.reradiation.size(); ++k) {
    const BinPair& pr = image.reradiation[k];
    if (pr.in < 0 || pr.in >= n || pr.out < 0 || pr.out >= n)
      throw InputError(input, "bispectral pair " + pair_text(image, pr) + " is outside the " + std::to_string(n) + " bins");
    if (pr.in == pr.out)
      throw InputError(input, "bispectral pair " + pair_text(image, pr) + " is on the diagonal (that is the T layer)");
    if (k > 0) {
      const BinPair& prev = image.reradiation[k - 1];
      if (std::make_pair(prev.in, prev.out) >= std::make_pair(pr.in, pr.out))
        throw InputError(input, "bispectral pairs are not sorted by (in, out) or repeat: " + pair_text(image, prev) +
                                    " before " + pair_text(image, pr));
    }
  }
  const std::size_t expected = image.pixel_count() * image.reradiation.size();
  for (const auto& light : image.lights) {
    if (light.reradiation.size() != expected && !(light.reradiation.empty() && expected == 0)) {
      throw InputError(input, "light \"" + light.name + "\" has " + std::to_string(light.reradiation.size()) +
                                  " bispectral values, expected width·height·pairs = " + std::to_string(expected));
    }
  }
}

std::vector<int> reradiation_in_bins(const SpectralImage& image) {
  std::set<int> in;
  for (const BinPair& pr : image.reradiation) in.insert(pr.in);
  return {in.begin(), in.end()};
}

void add_reradiated(const SpectralImage& image, int light, const std::vector<double>& e, std::vector<double>& radiance) {
  const std::size_t n = static_cast<std::size_t>(image.bins.size());
  const std::size_t np = image.reradiation.size();
  if (np == 0) return;
  const std::vector<float>& m = image.lights.at(static_cast<std::size_t>(light)).reradiation;
  if (e.size() != n || radiance.size() != image.pixel_count() * n || m.size() != image.pixel_count() * np)
    throw RuntimeError("add_reradiated: sizes do not match the image");
  for (std::size_t pix = 0; pix < image.pixel_count(); ++pix) {
    for (std::size_t k = 0; k < np; ++k) {
      const BinPair& pr = image.reradiation[k];
      radiance[pix * n + static_cast<std::size_t>(pr.out)] += static_cast<double>(m[pix * np + k]) * e[static_cast<std::size_t>(pr.in)];
    }
  }
}

std::vector<float> reradiation_colour_weights(const SpectralImage& image, int light,
                                              const Eigen::Matrix<double, 3, Eigen::Dynamic>& c_out,
                                              const std::vector<int>& in_bins) {
  const std::size_t np = image.reradiation.size();
  const std::size_t ni = in_bins.size();
  std::vector<float> k_out(image.pixel_count() * 3 * ni, 0.0f);
  if (np == 0) return k_out;
  const std::vector<float>& m = image.lights.at(static_cast<std::size_t>(light)).reradiation;
  if (c_out.cols() != image.bins.size() || m.size() != image.pixel_count() * np)
    throw RuntimeError("reradiation_colour_weights: sizes do not match the image");
  // Column of each pair's in bin among in_bins.
  std::vector<std::size_t> col(np);
  for (std::size_t k = 0; k < np; ++k) {
    const auto it = std::lower_bound(in_bins.begin(), in_bins.end(), image.reradiation[k].in);
    if (it == in_bins.end() || *it != image.reradiation[k].in)
      throw RuntimeError("reradiation_colour_weights: in bin missing from in_bins");
    col[k] = static_cast<std::size_t>(it - in_bins.begin());
  }
  std::vector<double> acc(3 * ni);
  for (std::size_t pix = 0; pix < image.pixel_count(); ++pix) {
    std::fill(acc.begin(), acc.end(), 0.0);
    for (std::size_t k = 0; k < np; ++k) {
      const double v = m[pix * np + k];
      const int out = image.reradiation[k].out;
      for (int c = 0; c < 3; ++c) acc[static_cast<std::size_t>(c) * ni + col[k]] += c_out(c, out) * v;
    }
    for (std::size_t j = 0; j < 3 * ni; ++j) k_out[pix * 3 * ni + j] = static_cast<float>(acc[j]);
  }
  return k_out;
}

Eigen::Matrix<double, 3, Eigen::Dynamic> reradiation_pair_xyz(const SpectralImage& image, const ColorMatching& cmf,
                                                              const LightSpectrum& light) {
  const std::size_t np = image.reradiation.size();
  Eigen::Matrix<double, 3, Eigen::Dynamic> w = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, static_cast<Eigen::Index>(np));
  if (np == 0 || light.off || light.scale == 0.0) return w;
  const BinLayout& bins = image.bins;
  const double y = relight_weights(cmf, light.spectrum, bins, LightUnits::Absolute).row(1).sum();
  if (!(y > 0.0)) return w;  // relight_weights refuses such a light before this is reached
  for (std::size_t q = 0; q < np; ++q) {
    const BinPair& pr = image.reradiation[q];
    const double e = light.scale / y * light.spectrum.integrate(bins.lo_nm(pr.in), bins.hi_nm(pr.in)) / bins.width_nm(pr.in);
    for (int c = 0; c < 3; ++c)
      w(c, static_cast<Eigen::Index>(q)) = cmf.channel(c).integrate(bins.lo_nm(pr.out), bins.hi_nm(pr.out)) * e;
  }
  return w;
}

namespace detail {

bool parse_reradiation_channel(const std::string& name, const std::string& path, ReradiationChannel& out) {
  // The reference library's re-radiation pattern, with an optional layer prefix in front:
  //   ^T\.(\d*,?\d*([Ee][+-]?\d+)?)(Y|Z|E|P|T|G|M|k|h|da|d|c|m|u|n|p)?(m|Hz)\.(…same…)$
  static const std::regex kPattern(
      R"(^(?:(.+)\.)?T\.(\d*,?\d*(?:[Ee][+-]?\d+)?)(Y|Z|E|P|T|G|M|k|h|da|d|c|m|u|n|p)?(m|Hz)\.(\d*,?\d*(?:[Ee][+-]?\d+)?)(Y|Z|E|P|T|G|M|k|h|da|d|c|m|u|n|p)?(m|Hz)$)");
  std::smatch m;
  if (!std::regex_match(name, m, kPattern)) return false;
  out.layer = m[1].matched ? m[1].str() : std::string();
  out.in_nm = to_nm(name, m[2].str(), m[3].matched ? m[3].str() : std::string(), m[4].str(), path);
  out.out_nm = to_nm(name, m[5].str(), m[6].matched ? m[6].str() : std::string(), m[7].str(), path);
  out.name = name;
  return true;
}

// The top level of a bispectral file, for readers of the published layout (JCGT 2021; its reference
// library reads a re-radiation matrix only when it holds every pair with λin < λout, and no other):
// the lights' sum (at `sum`, pairs as image.reradiation) for every pair in < out, and 0 where the
// image holds none (one shared row of zeros, y stride 0: no memory per pixel, PIZ stores almost nothing
// of it; OpenEXR 3.1 does not take an x stride of 0). Pairs with λin > λout (an absorption and an emission spectrum that overlap: light absorbed
// in one bin re-emitted in a shorter one, as Prizma's model of a dye allows) have no place in that
// layout: they are in the light layers only, which Prizma reads.
void add_published_pairs(const SpectralImage& image, const char* sum, Imf::PixelType type, Imf::Header& header,
                         Imf::FrameBuffer& fb, ReradiationBuffers& keep) {
  const std::size_t np = image.reradiation.size();
  const std::size_t elem = type == Imf::HALF ? sizeof(half) : sizeof(float);
  const std::size_t x_stride = elem * np;
  const std::size_t y_stride = x_stride * static_cast<std::size_t>(image.width);
  const auto row = static_cast<std::size_t>(image.width);
  const char* zero = type == Imf::HALF ? reinterpret_cast<const char*>(keep.halves.emplace_back(row, half(0.0f)).data())
                                       : reinterpret_cast<const char*>(keep.floats.emplace_back(row, 0.0f).data());
  const int n = image.bins.size();
  for (int in = 0; in < n; ++in) {
    for (int out = in + 1; out < n; ++out) {
      const auto held = std::find(image.reradiation.begin(), image.reradiation.end(), BinPair{in, out});
      const std::string name = reradiation_channel_name(image.bins.centre_nm(in), image.bins.centre_nm(out), "");
      header.channels().insert(name, Imf::Channel(type));
      if (held == image.reradiation.end()) {
        fb.insert(name, Imf::Slice(type, const_cast<char*>(zero), elem, 0));
      } else {
        const auto k = static_cast<std::size_t>(held - image.reradiation.begin());
        fb.insert(name, Imf::Slice(type, const_cast<char*>(sum + elem * k), x_stride, y_stride));
      }
    }
  }
}

std::uint64_t add_reradiation_for_write(const SpectralImage& image, bool multi, bool half_out, Imf::Header& header,
                                        Imf::FrameBuffer& fb, ReradiationBuffers& keep, const std::string& path) {
  check_reradiation_layout(image, path);
  const std::size_t np = image.reradiation.size();
  if (np == 0) return 0;
  const std::size_t count = image.pixel_count() * np;
  for (const auto& light : image.lights) {
    for (std::size_t k = 0; k < count; ++k) {
      if (!std::isfinite(light.reradiation[k])) {
        const std::size_t pix = k / np;
        std::ostringstream os;
        os << "bispectral values of light \"" << light.name << "\": " << (std::isnan(light.reradiation[k]) ? "NaN" : "infinite value")
           << " at pixel (" << pix % static_cast<std::size_t>(image.width) << ", " << pix / static_cast<std::size_t>(image.width)
           << "), " << pair_text(image, image.reradiation[k % np]);
        throw InputError(path, os.str());
      }
    }
  }
  // The layers to write: each light (prefix) when multi, plus the sum at top level; else top level.
  // (Prizma writes every bispectral file with named layers: exr::has_named_layers.)
  std::vector<std::pair<std::string, const std::vector<float>*>> layers;
  if (multi) {
    auto& sum = keep.floats.emplace_back(count, 0.0f);
    for (std::size_t k = 0; k < count; ++k) {
      double s = 0.0;
      for (const auto& light : image.lights) s += light.reradiation[k];
      sum[k] = static_cast<float>(s);
    }
    layers.emplace_back("", &sum);
    for (const auto& light : image.lights) layers.emplace_back(light.name, &light.reradiation);
  } else {
    layers.emplace_back("", &image.lights.front().reradiation);
  }
  std::uint64_t checksum = 0;
  const Imf::PixelType type = half_out ? Imf::HALF : Imf::FLOAT;
  const std::size_t elem = half_out ? sizeof(half) : sizeof(float);
  const std::size_t x_stride = elem * np;
  const std::size_t y_stride = x_stride * static_cast<std::size_t>(image.width);
  for (std::size_t li = 0; li < layers.size(); ++li) {
    const auto& [layer, values] = layers[li];
    const bool summed = multi && li == 0;  // the top-level sum is not read back: not in the checksum
    const char* base = reinterpret_cast<const char*>(values->data());
    if (half_out) {
      auto& hb = keep.halves.emplace_back(count);
      std::vector<float> back(count);
      for (std::size_t k = 0; k < count; ++k) {
        const float v = (*values)[k];
        if (std::fabs(v) > kHalfMax)
          throw InputError(path, "bispectral value " + std::to_string(v) + " exceeds half's range (65504); write float");
        hb[k] = half(v);
        back[k] = static_cast<float>(hb[k]);
      }
      if (!summed) checksum += hash_values(back.data(), count);
      base = reinterpret_cast<const char*>(hb.data());
    } else if (!summed) {
      checksum += hash_values(values->data(), count);
    }
    if (summed) {
      add_published_pairs(image, base, type, header, fb, keep);
      continue;
    }
    for (std::size_t k = 0; k < np; ++k) {
      const BinPair& pr = image.reradiation[k];
      const std::string name = reradiation_channel_name(image.bins.centre_nm(pr.in), image.bins.centre_nm(pr.out), layer);
      header.channels().insert(name, Imf::Channel(type));
      fb.insert(name, Imf::Slice(type, const_cast<char*>(base + elem * k), x_stride, y_stride));
    }
  }
  return checksum;
}

void add_reradiation_for_read(const std::vector<ReradiationChannel>& channels, const std::vector<std::string>& layers,
                              const std::vector<double>& lambdas, SpectralImage& image, Imf::FrameBuffer& fb,
                              const Imath::Box2i& dw, const std::string& path) {
  if (channels.empty()) return;
  auto bin_of = [&](double nm, const std::string& name) {
    for (std::size_t i = 0; i < lambdas.size(); ++i)
      if (std::abs(lambdas[i] - nm) <= 1e-4) return static_cast<int>(i);
    std::ostringstream os;
    os << "bispectral channel \"" << name << "\": " << nm << " nm is not the wavelength of any T.<λ>nm channel";
    throw InputError(path, os.str());
  };
  // Per light layer: pair → channel name.
  std::map<std::string, std::map<std::pair<int, int>, std::string>> by_layer;
  for (const ReradiationChannel& ch : channels) {
    if (std::find(layers.begin(), layers.end(), ch.layer) == layers.end()) continue;
    const int in = bin_of(ch.in_nm, ch.name), out = bin_of(ch.out_nm, ch.name);
    if (in == out)
      throw InputError(path, "bispectral channel \"" + ch.name + "\" has the same wavelength twice (the diagonal is T.<λ>nm)");
    if (!by_layer[ch.layer].emplace(std::make_pair(in, out), ch.name).second)
      throw InputError(path, "bispectral channels \"" + by_layer[ch.layer][{in, out}] + "\" and \"" + ch.name +
                                 "\" are the same pair of wavelengths");
  }
  if (by_layer.empty()) return;
  const auto& first = by_layer.begin()->second;
  for (const std::string& layer : layers) {
    const auto it = by_layer.find(layer);
    const std::string what = layer.empty() ? "the top-level layer" : "layer \"" + layer + "\"";
    if (it == by_layer.end() || it->second.size() != first.size() ||
        !std::equal(first.begin(), first.end(), it->second.begin(), [](const auto& a, const auto& b) { return a.first == b.first; })) {
      throw InputError(path, what + " has " + std::to_string(it == by_layer.end() ? 0 : it->second.size()) +
                                 " bispectral channels, another light layer " + std::to_string(first.size()) +
                                 ": light layers must share their bispectral channels");
    }
  }
  for (const auto& [pair, name] : first) image.reradiation.push_back({pair.first, pair.second});
  const std::size_t np = image.reradiation.size();
  const std::size_t x_stride = sizeof(float) * np;
  const std::size_t y_stride = x_stride * static_cast<std::size_t>(image.width);
  for (std::size_t l = 0; l < layers.size(); ++l) {
    std::vector<float>& dest = image.lights[l].reradiation;
    dest.assign(image.pixel_count() * np, 0.0f);
    const auto& names = by_layer.at(layers[l]);
    std::size_t k = 0;
    for (const auto& [pair, name] : names) {
      fb.insert(name, Imf::Slice::Make(Imf::FLOAT, dest.data() + k, dw, x_stride, y_stride));
      ++k;
    }
  }
}

void check_reradiation_finite(const SpectralImage& image, const std::string& path) {
  const std::size_t np = image.reradiation.size();
  if (np == 0) return;
  for (const auto& light : image.lights) {
    for (std::size_t k = 0; k < light.reradiation.size(); ++k) {
      if (!std::isfinite(light.reradiation[k])) {
        const std::size_t pix = k / np;
        std::ostringstream os;
        os << "bispectral values of layer \"" << light.name << "\": " << (std::isnan(light.reradiation[k]) ? "NaN" : "infinite value")
           << " at pixel (" << pix % static_cast<std::size_t>(image.width) << ", " << pix / static_cast<std::size_t>(image.width)
           << "), " << pair_text(image, image.reradiation[k % np]);
        throw InputError(path, os.str());
      }
    }
  }
}

std::uint64_t reradiation_checksum(const SpectralImage& image) {
  std::uint64_t sum = 0;
  if (image.reradiation.empty()) return 0;
  for (const auto& light : image.lights) sum += hash_values(light.reradiation.data(), light.reradiation.size());
  return sum;
}

}  // namespace detail
}  // namespace prizma::spectral
