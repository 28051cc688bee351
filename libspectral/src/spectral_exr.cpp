// The spectral OpenEXR layout (docs/spectral-exr.md), read and written through OpenEXR's C++ API.
// Fichet, Pacanowski, Wilkie, "An OpenEXR Layout for Spectral Images", JCGT 10(3), 2021: reflective
// channels T.<λ>nm (comma decimal separator), spectralLayoutVersion "1.0". Prizma adds one layer per
// light (when there are two or more), variance layers and prizma: attributes.
#include "prizma/spectral/spectral_exr.h"

#include <ImathBox.h>
#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <ImfFloatVectorAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfDoubleAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfIntAttribute.h>
#include <ImfMatrixAttribute.h>
#include <ImfVecAttribute.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>
#include <ImfTestFile.h>
#include <half.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <list>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "prizma/spectral/atomic_file.h"
#include "prizma/spectral/bispectral.h"
#include "prizma/spectral/colour.h"
#include "prizma/spectral/colour_matching.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/input_file.h"
#include "prizma/spectral/light_spectrum.h"
#include "prizma/spectral/output_group.h"
#include "prizma/spectral/tool_main.h"
#include "bispectral_exr.h"
#include "coefficients_exr.h"
#include "float_hash.h"
#include "missing_channels.h"
#include "text_util.h"

namespace prizma::spectral {
namespace {

namespace fs = std::filesystem;

constexpr const char* kLayoutVersion = "1.0";
constexpr const char* kAttrEdges = "prizma:binEdgesNm";
// The same edges as decimal text with 17 significant digits: the float vector above loses the
// double precision of BinLayout, this restores it exactly (readers that do not know it ignore it).
constexpr const char* kAttrEdgesExact = "prizma:binEdgesNmExact";
constexpr const char* kAttrLights = "prizma:lights";
constexpr const char* kAttrSamples = "prizma:samples";
constexpr const char* kAttrSampleRange = "prizma:sampleRange";
constexpr const char* kAttrSeed = "prizma:seed";
constexpr const char* kAttrSceneHash = "prizma:sceneHash";
constexpr const char* kAttrVersion = "prizma:version";
constexpr const char* kAttrWavelengthSampling = "prizma:wavelengthSampling";
constexpr const char* kAttrChecksum = "prizma:checksum";
constexpr const char* kAttrScenePath = "prizma:scenePath";
constexpr const char* kAttrRenderOptions = "prizma:renderOptions";
// Checksum versions (the value's prefix): v2 also covers the top-level T layer of a file with two or
// more lights (the sum of the lights); v1, written before it, covers the light and variance layers.
constexpr const char* kChecksumScheme = "fnv1a64-words-v2:";
constexpr const char* kChecksumSchemeV1 = "fnv1a64-words:";
constexpr const char* kVarianceLayer = "var";
constexpr float kHalfMax = 65504.0f;
constexpr double kSpeedOfLight_m_per_s = 299792458.0;

std::string path_string(const fs::path& p) { return p.string(); }

// Threads for compressing and decompressing chunks. The count given to Imf::InputFile/OutputFile is
// only how many chunks may be in flight: the work runs on OpenEXR's global thread pool, which has no
// threads until it is given some, so without setGlobalThreadCount every file was decoded on one core
// (a 512×512, 32-bin, two-light PIZ file read in 1.35 s).
int io_threads() {
  static const int count = [] {
    const unsigned hc = std::thread::hardware_concurrency();
    const int n = static_cast<int>(std::clamp(hc, 1u, 8u));
    if (Imf::globalThreadCount() < n) Imf::setGlobalThreadCount(n);
    return n;
  }();
  return count;
}

// Pixel data of at most this many bytes (all channels, as stored) are written uncompressed, larger
// images with PIZ (docs/spectral-exr.md, "Compression"). PIZ encodes 15–30 MB of floats per CPU
// second (a 24×24, 35-channel image: 5–7 ms, more than rendering it at 1 spp) and saved nothing on
// such renders (bench_peer.json at 1–256 spp: 81.96 KB PIZ, 82.33 KB uncompressed); below 1 MiB
// the most any compression could save is a few hundred KB.
constexpr std::size_t kUncompressedMaxBytes = std::size_t{1} << 20;

std::size_t stored_pixel_bytes(const Imf::Header& h) {
  const Imath::Box2i dw = h.dataWindow();
  const auto pixels = static_cast<std::size_t>(std::max(0, dw.max.x - dw.min.x + 1)) *
                      static_cast<std::size_t>(std::max(0, dw.max.y - dw.min.y + 1));
  std::size_t per_pixel = 0;
  for (auto it = h.channels().begin(); it != h.channels().end(); ++it)
    per_pixel += it.channel().type == Imf::HALF ? sizeof(half) : sizeof(float);
  return pixels * per_pixel;
}

// The compression Prizma writes for a file of this header's size and channels.
Imf::Compression prizma_compression(const Imf::Header& h) {
  return stored_pixel_bytes(h) <= kUncompressedMaxBytes ? Imf::NO_COMPRESSION : Imf::PIZ_COMPRESSION;
}

bool valid_light_name(std::string_view name) {
  if (name.empty()) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
}

// ---------------------------------------------------------------------------------------------
// Channel names

struct ParsedChannel {
  std::string layer;  // text before the spectral part ("" for top level, "key", "key.var", "var")
  bool emissive = false;
  double lambda_nm = 0.0;
};

double unit_prefix_factor(const std::string& prefix) {
  static const std::map<std::string, double> kFactors = {
      {"Y", 1e24}, {"Z", 1e21}, {"E", 1e18}, {"P", 1e15}, {"T", 1e12}, {"G", 1e9},  {"M", 1e6},  {"k", 1e3},
      {"h", 1e2},  {"da", 1e1}, {"", 1.0},   {"d", 1e-1}, {"c", 1e-2}, {"m", 1e-3}, {"u", 1e-6}, {"n", 1e-9},
      {"p", 1e-12}};
  return kFactors.at(prefix);
}

// The reference reader's pattern (JCGT 2021, section 3), with an optional layer prefix in front:
//   ^((S([0-3]))|T)\.(\d*,?\d*([Ee][+-]?\d+)?)(Y|Z|E|P|T|G|M|k|h|da|d|c|m|u|n|p)?(m|Hz)$
// Returns nullopt for channels that are not spectral (R, G, B, …). Throws InputError for a spectral
// channel whose number is not a positive finite wavelength.
std::optional<ParsedChannel> parse_channel_name(const std::string& name, const std::string& path) {
  static const std::regex kPattern(
      R"(^(?:(.+)\.)?(S[0-3]|T)\.(\d*,?\d*(?:[Ee][+-]?\d+)?)(Y|Z|E|P|T|G|M|k|h|da|d|c|m|u|n|p)?(m|Hz)$)");
  std::smatch m;
  if (!std::regex_match(name, m, kPattern)) return std::nullopt;
  ParsedChannel out;
  out.layer = m[1].matched ? m[1].str() : std::string();
  out.emissive = m[2].str() != "T";
  std::string number = m[3].str();
  std::replace(number.begin(), number.end(), ',', '.');
  double value = 0.0;
  if (!detail::parse_double(number, value) || !std::isfinite(value) || value <= 0.0) {
    throw InputError(path, "channel \"" + name + "\": \"" + m[3].str() + "\" is not a positive wavelength");
  }
  value *= unit_prefix_factor(m[4].matched ? m[4].str() : std::string());
  // Metres → nm, or frequency in Hz → wavelength λ = c / f.
  out.lambda_nm = (m[5].str() == "Hz") ? kSpeedOfLight_m_per_s / value * 1e9 : value * 1e9;
  if (!std::isfinite(out.lambda_nm) || out.lambda_nm <= 0.0) {
    throw InputError(path, "channel \"" + name + "\": wavelength out of range");
  }
  return out;
}

std::string layer_prefix(std::string_view layer) { return layer.empty() ? std::string() : std::string(layer) + "."; }

// ---------------------------------------------------------------------------------------------
// Writing

void check_finite(const std::vector<float>& values, int width, int bins, const std::string& what,
                  const std::string& path) {
  for (std::size_t k = 0; k < values.size(); ++k) {
    if (!std::isfinite(values[k])) {
      const std::size_t pixel = k / static_cast<std::size_t>(bins);
      std::ostringstream os;
      os << what << ": " << (std::isnan(values[k]) ? "NaN" : "infinite value") << " at pixel ("
         << pixel % static_cast<std::size_t>(width) << ", " << pixel / static_cast<std::size_t>(width) << "), bin "
         << k % static_cast<std::size_t>(bins);
      throw InputError(path, os.str());
    }
  }
}

std::vector<std::string> layer_names(const SpectralImage& image) {
  std::vector<std::string> names;
  for (const auto& l : image.lights) names.push_back(l.name);
  return names;
}

void put_int_or_string(Imf::Header& header, const char* name, std::int64_t v) {
  if (v >= std::numeric_limits<int>::min() && v <= std::numeric_limits<int>::max()) {
    header.insert(name, Imf::IntAttribute(static_cast<int>(v)));
  } else {
    header.insert(name, Imf::StringAttribute(std::to_string(v)));
  }
}

// prizma:seed: an int when it fits (every file before 0.3 too), else its unsigned decimal string.
// (Files before 0.3 stored seeds ≥ 2^63 as negative numbers, the seed minus 2^64: read_seed.)
void put_seed(Imf::Header& header, const char* name, std::uint64_t seed) {
  if (seed <= static_cast<std::uint64_t>(std::numeric_limits<int>::max())) {
    header.insert(name, Imf::IntAttribute(static_cast<int>(seed)));
  } else {
    header.insert(name, Imf::StringAttribute(std::to_string(seed)));
  }
}

// One channel set to write: a name prefix and a pixel-major, bin-contiguous float buffer.
enum class LayerKind { Sum, Light, Variance };

struct OutLayer {
  std::string prefix;  // "" / "key." / "var." / "key.var."
  const std::vector<float>* data;
  std::string what;    // for messages
  LayerKind kind;
};

// The pixel checksum (prizma:checksum): per light layer and per variance layer, FNV-1a 64 over the
// values as a reader gets them (float32 bit patterns, one 32-bit word per step), with different
// offset bases for transport and variance; the per-layer hashes are summed modulo 2⁶⁴ so that the
// order of the layers does not matter. It covers the pixels, not the header.
constexpr std::uint64_t kFnvBasisLight = 0xcbf29ce484222325ULL;
constexpr std::uint64_t kFnvBasisVariance = 0x84222325cbf29ce4ULL;
constexpr std::uint64_t kFnvBasisSum = 0xe4842223cbf2925cULL;  // the top-level T layer (v2)

// OpenEXR's output stream over write_atomically's checked temporary: a failed write throws (OpenEXR
// is C++), and AtomicOutput keeps the system's reason for the message.
class AtomicOStream final : public Imf::OStream {
 public:
  explicit AtomicOStream(AtomicOutput& out) : Imf::OStream(out.temporary().c_str()), m_out(out) {}
  void write(const char c[], int n) override {
    if (n < 0 || !m_out.write(c, static_cast<std::size_t>(n))) throw RuntimeError(m_out.error());
  }
  uint64_t tellp() override { return static_cast<uint64_t>(m_out.tell()); }
  void seekp(uint64_t pos) override {
    if (!m_out.seek(static_cast<std::int64_t>(pos))) throw RuntimeError(m_out.error());
  }

 private:
  AtomicOutput& m_out;
};

std::string checksum_string(std::uint64_t sum, const char* scheme = kChecksumScheme) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(sum));
  return std::string(scheme) + buf;
}

// v1: the light and variance layers, summed over layers modulo 2⁶⁴.
std::uint64_t light_layers_hash(const SpectralImage& image) {
  std::uint64_t sum = 0;
  for (const auto& light : image.lights) {
    if (light.data.empty()) continue;  // a compact file: coefficients only
    sum += detail::hash_float_bits(light.data.data(), light.data.size(), kFnvBasisLight);
    if (!light.variance.empty()) sum += detail::hash_float_bits(light.variance.data(), light.variance.size(), kFnvBasisVariance);
  }
  return sum;
}

// The top-level T layer of a file with two or more lights: per value the float of the double sum over
// the lights (what the writer stores).
std::vector<float> sum_of_lights(const SpectralImage& image) {
  const std::size_t n = image.lights.empty() ? 0 : image.lights.front().data.size();
  std::vector<float> sum(n, 0.0f);
  for (std::size_t k = 0; k < n; ++k) {
    double s = 0.0;
    for (const auto& light : image.lights) s += light.data[k];
    sum[k] = static_cast<float>(s);
  }
  return sum;
}

// The preview channels R, G, B, for viewers that do not read spectra (JCGT 2021 recommends them): the
// default relight, as prizma-relight makes it without options (each light at the spectrum recorded
// in prizma:lights, else D65; CIE 1931 2°; a perfect white at Y = 1; exposure 0), in linear sRGB
// (IEC 61966-2-1 primaries, D65 white). A light whose recorded spectrum cannot be used here (a csv:
// left on another machine) is left out, as prizma-relight leaves it off; empty when every light is,
// or the CIE tables cannot be read.
std::vector<float> preview_rgb(const SpectralImage& image) {
  const ColorMatching* cmf = nullptr;
  try {
    cmf = &ColorMatching::get(Observer::Cie1931_2deg);
  } catch (const std::exception&) {
    return {};
  }
  const Eigen::Matrix3d to_rgb = xyz_to_linear_srgb_matrix();
  const int n = image.bins.size();
  std::vector<Eigen::Matrix<double, 3, Eigen::Dynamic>> weights;  // per light, RGB ← bins
  std::vector<Eigen::Matrix<double, 3, Eigen::Dynamic>> rerad;    // per light, RGB ← bispectral pairs
  bool any = false;
  for (const auto& layer : image.lights) {
    const std::string spec = default_spectrum(image.info.light_records, layer.name, image.lights.size());
    Eigen::Matrix<double, 3, Eigen::Dynamic> w = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, n);
    Eigen::Matrix<double, 3, Eigen::Dynamic> r =
        Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, static_cast<Eigen::Index>(image.reradiation.size()));
    try {
      const LightSpectrum light = parse_light_spectrum(spec);
      if (!light.off) {
        w = to_rgb * relight_weights(*cmf, light, image.bins);
        r = to_rgb * reradiation_pair_xyz(image, *cmf, light);  // fluorescent files: the re-radiated light too
        if (layer.data.empty()) {  // compact: RGB ← coefficients through the basis (n×k, vector-major)
          const int k = layer.coefficients.k;
          const Eigen::Map<const Eigen::MatrixXf> basis(layer.coefficients.basis.data(), n, k);
          w = Eigen::Matrix<double, 3, Eigen::Dynamic>(w * basis.cast<double>());
        }
        any = true;
      }
    } catch (const std::exception&) {
      // left out (off)
    }
    weights.push_back(std::move(w));
    rerad.push_back(std::move(r));
  }
  const std::size_t np = image.reradiation.size();
  if (!any) return {};
  std::vector<float> rgb(image.pixel_count() * 3);
  for (std::size_t px = 0; px < image.pixel_count(); ++px) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::size_t l = 0; l < image.lights.size(); ++l) {
      const TransportLayer& layer = image.lights[l];
      const int m = layer.data.empty() ? layer.coefficients.k : n;
      const float* t = layer.data.empty() ? layer.coefficients.values.data() + px * static_cast<std::size_t>(m)
                                          : layer.data.data() + px * static_cast<std::size_t>(n);
      for (int i = 0; i < m; ++i) sum += weights[l].col(i) * static_cast<double>(t[i]);
      if (np > 0) {
        const float* rm = layer.reradiation.data() + px * np;
        for (std::size_t q = 0; q < np; ++q) sum += rerad[l].col(static_cast<Eigen::Index>(q)) * static_cast<double>(rm[q]);
      }
    }
    for (int c = 0; c < 3; ++c) rgb[3 * px + static_cast<std::size_t>(c)] = std::isfinite(sum[c]) ? static_cast<float>(sum[c]) : 0.0f;
  }
  return rgb;
}

}  // namespace

std::string spectral_pixel_checksum(const SpectralImage& image) {
  std::uint64_t sum = light_layers_hash(image);
  if (image.lights.size() >= 2) {
    const std::vector<float> total = sum_of_lights(image);
    sum += detail::hash_float_bits(total.data(), total.size(), kFnvBasisSum);
  }
  sum += detail::reradiation_checksum(image);  // 0 without bispectral terms
  sum += detail::coefficients_checksum(image);  // 0 without spectral-basis coefficients
  return checksum_string(sum);
}

int SpectralImage::find_light(std::string_view name) const {
  for (std::size_t i = 0; i < lights.size(); ++i) {
    if (lights[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

std::string spectral_channel_name(double lambda_nm, std::string_view layer) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, lambda_nm, std::chars_format::fixed, 6);
  std::string number(buf, res.ptr);
  std::replace(number.begin(), number.end(), '.', ',');
  return layer_prefix(layer) + "T." + number + "nm";
}

void check_exr_light_name(std::string_view name, const std::string& input) {
  if (!valid_light_name(name)) {
    throw InputError(input, "light name \"" + std::string(name) + "\" is not valid (letters, digits, '_' and '-' only)");
  }
  if (name == kVarianceLayer) {
    throw InputError(input, "light name \"var\" is reserved for the variance layers (docs/spectral-exr.md)");
  }
}

void check_exr_bin_names(const BinLayout& bins, const std::string& input) {
  for (int i = 1; i < bins.size(); ++i) {
    const std::string a = spectral_channel_name(bins.centre_nm(i - 1));
    if (a == spectral_channel_name(bins.centre_nm(i))) {
      std::ostringstream os;
      os.precision(12);
      os << "bins " << i - 1 << " and " << i << " (centres " << bins.centre_nm(i - 1) << " and " << bins.centre_nm(i)
         << " nm) both get the channel name " << a
         << ": channel names hold the centre to 6 decimals, so bins must be wider";
      throw InputError(input, os.str());
    }
  }
}

void write_spectral_exr(const fs::path& path, const SpectralImage& image, const ExrWriteOptions& opts) {
  const std::string p = path_string(path);
  // Validate the image: sizes, names, finite values.
  if (image.width <= 0 || image.height <= 0) {
    throw InputError(p, "image size " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                            " is empty");
  }
  if (image.lights.empty()) throw InputError(p, "the image has no light layers");
  const int bins = image.bins.size();
  const std::size_t expected = image.pixel_count() * static_cast<std::size_t>(bins);
  // Compact: spectral-basis coefficients only, no bins (prizma-relight compress --compact).
  const bool compact = image.compact();
  if (compact && !image.reradiation.empty()) throw InputError(p, "a compact file cannot hold bispectral (fluorescent) terms");
  std::set<std::string> names;
  for (const auto& light : image.lights) {
    check_exr_light_name(light.name, p);
    if (!names.insert(light.name).second) throw InputError(p, "two lights are named \"" + light.name + "\"");
    if (compact) {
      if (!light.variance.empty()) throw InputError(p, "light \"" + light.name + "\": a compact file has no variance layers");
      continue;
    }
    if (light.data.size() != expected) {
      throw InputError(p, "light \"" + light.name + "\" has " + std::to_string(light.data.size()) +
                              " values, expected width·height·bins = " + std::to_string(expected));
    }
    if (!light.variance.empty() && light.variance.size() != expected) {
      throw InputError(p, "light \"" + light.name + "\" has " + std::to_string(light.variance.size()) +
                              " variance values, expected " + std::to_string(expected));
    }
    check_finite(light.data, image.width, bins, "light \"" + light.name + "\"", p);
    if (opts.write_variance) check_finite(light.variance, image.width, bins, "variance of light \"" + light.name + "\"", p);
  }

  // The layers: top level (sum of all lights), per light when there are two or more, variance.
  const bool multi = image.lights.size() >= 2;
  std::vector<float> sum;
  std::vector<OutLayer> layers;
  if (compact) {
    // no transport layers
  } else if (multi) {
    sum = sum_of_lights(image);
    check_finite(sum, image.width, bins, "sum of all lights", p);
    layers.push_back({"", &sum, "sum of all lights", LayerKind::Sum});
    for (const auto& light : image.lights) {
      layers.push_back({light.name + ".", &light.data, "light \"" + light.name + "\"", LayerKind::Light});
    }
    if (opts.write_variance) {
      for (const auto& light : image.lights) {
        if (!light.variance.empty()) {
          layers.push_back({light.name + ".var.", &light.variance, "variance of light \"" + light.name + "\"",
                            LayerKind::Variance});
        }
      }
    }
  } else {
    const auto& light = image.lights.front();
    layers.push_back({"", &light.data, "light \"" + light.name + "\"", LayerKind::Light});
    if (opts.write_variance && !light.variance.empty()) {
      layers.push_back({"var.", &light.variance, "variance of light \"" + light.name + "\"", LayerKind::Variance});
    }
  }

  // Channel names, refusing two bins whose centres print the same.
  std::vector<std::string> suffixes;
  for (int i = 0; i < bins; ++i) suffixes.push_back(spectral_channel_name(image.bins.centre_nm(i)));
  check_exr_bin_names(image.bins, p);

  // Half: refuse (or clamp) values beyond half's range, then convert.
  const bool half_out = opts.pixel_type == ExrPixelType::Half;
  std::list<std::vector<half>> half_buffers;
  if (half_out) {
    std::size_t clamped = 0;
    for (const auto& layer : layers) {
      auto& hb = half_buffers.emplace_back(expected);
      for (std::size_t k = 0; k < expected; ++k) {
        float v = (*layer.data)[k];
        if (std::fabs(v) > kHalfMax) {
          if (!opts.clamp_half) {
            throw InputError(p, layer.what + ": value " + std::to_string(v) +
                                    " exceeds half's range (65504); write float, or clamp");
          }
          v = std::copysign(kHalfMax, v);
          ++clamped;
        }
        hb[k] = half(v);
      }
    }
    if (clamped > 0) {
      std::cerr << "warning: " << p << ": " << clamped << " value" << (clamped == 1 ? "" : "s")
                << " beyond half's range clamped to 65504\n";
    }
  }

  // Preview channels R, G, B (derived from the layers, so outside the checksum); half files clamp them
  // to half's range.
  const std::vector<float> preview = opts.write_preview ? preview_rgb(image) : std::vector<float>();
  std::vector<half> preview_half;
  if (half_out) {
    for (const float v : preview) preview_half.emplace_back(std::clamp(v, -kHalfMax, kHalfMax));
  }

  // Checksum of what a reader will get back (half files: the values after conversion to half).
  std::uint64_t checksum = 0;
  {
    auto half_it = half_buffers.begin();
    for (const auto& layer : layers) {
      const half* hv = half_out ? (half_it++)->data() : nullptr;
      const std::uint64_t basis = layer.kind == LayerKind::Light   ? kFnvBasisLight
                                  : layer.kind == LayerKind::Sum ? kFnvBasisSum
                                                                 : kFnvBasisVariance;
      checksum += half_out ? detail::hash_float_bits(hv, expected, basis) : detail::hash_float_bits(layer.data->data(), expected, basis);
    }
  }

  // Header: channels and attributes.
  Imf::Header header(image.width, image.height);
  const Imf::PixelType type = half_out ? Imf::HALF : Imf::FLOAT;
  for (const auto& layer : layers) {
    for (int i = 0; i < bins; ++i) header.channels().insert(layer.prefix + suffixes[i], Imf::Channel(type));
  }
  if (!preview.empty()) {
    for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(type));
  }
  header.insert("spectralLayoutVersion", Imf::StringAttribute(kLayoutVersion));
  {
    Imf::FloatVector edges;
    std::string exact;
    for (double e : image.bins.edges_nm()) {
      edges.push_back(static_cast<float>(e));
      char buf[64];
      const auto res = std::to_chars(buf, buf + sizeof buf, e, std::chars_format::general, 17);
      if (!exact.empty()) exact += ' ';
      exact.append(buf, res.ptr);
    }
    header.insert(kAttrEdges, Imf::FloatVectorAttribute(edges));
    header.insert(kAttrEdgesExact, Imf::StringAttribute(exact));
  }
  const SpectralExrInfo& info = image.info;
  check_light_records(info.light_records, layer_names(image), p);
  header.insert(kAttrLights, Imf::StringAttribute(light_records_json(
                                 info.light_records.empty() ? light_records_for(layer_names(image)) : info.light_records)));
  put_int_or_string(header, kAttrSamples, info.samples);
  put_seed(header, kAttrSeed, info.seed);
  if (!info.sample_range.empty()) header.insert(kAttrSampleRange, Imf::StringAttribute(info.sample_range));
  if (!info.scene_hash.empty()) header.insert(kAttrSceneHash, Imf::StringAttribute(info.scene_hash));
  header.insert(kAttrVersion, Imf::StringAttribute(info.version.empty() ? prizma_version() : info.version));
  if (!info.wavelength_sampling.empty()) {
    header.insert(kAttrWavelengthSampling, Imf::StringAttribute(info.wavelength_sampling));
  }
  if (!info.scene_path.empty()) header.insert(kAttrScenePath, Imf::StringAttribute(info.scene_path));
  if (!info.render_options.empty()) header.insert(kAttrRenderOptions, Imf::StringAttribute(info.render_options));
  header.insert(kAttrChecksum, Imf::StringAttribute(checksum_string(checksum)));

  // Frame buffer: slices point straight into the pixel-major, bin-contiguous buffers (bin i of pixel
  // (x, y) at base + i, x stride = bins values, y stride = width·bins values).
  Imf::FrameBuffer fb;
  const std::size_t elem = half_out ? sizeof(half) : sizeof(float);
  const std::size_t x_stride = elem * static_cast<std::size_t>(bins);
  const std::size_t y_stride = x_stride * static_cast<std::size_t>(image.width);
  auto half_it = half_buffers.begin();
  for (const auto& layer : layers) {
    const char* base = half_out ? reinterpret_cast<const char*>((half_it++)->data())
                                : reinterpret_cast<const char*>(layer.data->data());
    for (int i = 0; i < bins; ++i) {
      fb.insert(layer.prefix + suffixes[i],
                Imf::Slice(type, const_cast<char*>(base + elem * static_cast<std::size_t>(i)), x_stride, y_stride));
    }
  }
  // Bispectral channels (fluorescence; none, and the header unchanged, for a diagonal image).
  detail::ReradiationBuffers rerad_buffers;
  if (const std::uint64_t rc = detail::add_reradiation_for_write(image, multi, half_out, header, fb, rerad_buffers, p); rc != 0) {
    checksum += rc;
    header.insert(kAttrChecksum, Imf::StringAttribute(checksum_string(checksum)));
  }
  // Spectral-basis coefficients (half whatever the pixel type; none for most files).
  if (const std::uint64_t cc = detail::add_coefficients_for_write(image, multi, header, fb, p, half_buffers); cc != 0) {
    header.insert(kAttrChecksum, Imf::StringAttribute(checksum_string(checksum + cc)));
  }
  if (!preview.empty()) {
    const char* base = half_out ? reinterpret_cast<const char*>(preview_half.data())
                                : reinterpret_cast<const char*>(preview.data());
    const std::size_t stride = 3 * elem;
    for (std::size_t c = 0; c < 3; ++c) {
      fb.insert(c == 0 ? "R" : c == 1 ? "G" : "B",
                Imf::Slice(type, const_cast<char*>(base + elem * c), stride, stride * static_cast<std::size_t>(image.width)));
    }
  }

  // Compression, now that every channel is in the header: none for a small image, else PIZ (lossless
  // wavelet + Huffman: on noisy Monte Carlo float data it gave files ~25 % smaller than ZIP and wrote
  // about twice as fast; 512×512×32 floats: PIZ 23.7 MB, ZIP 31.4 MB, none 33.6 MB).
  header.compression() = prizma_compression(header);
  const bool compressed = header.compression() != Imf::NO_COMPRESSION;

  write_atomically(path, [&](AtomicOutput& out) {
    try {
      AtomicOStream stream(out);
      // OpenEXR's thread count: 0 encodes in this thread, n ≥ 1 keeps n chunks in flight on its pool.
      // Uncompressed chunks are only copied: no pool (starting its threads costs more than they save).
      int in_flight = 0;
      if (compressed && opts.threads != 1) in_flight = opts.threads > 1 ? std::min(opts.threads, io_threads()) : io_threads();
      Imf::OutputFile file(stream, header, in_flight);
      file.setFrameBuffer(fb);
      file.writePixels(image.height);
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      // OpenEXR's threads that cannot start (EAGAIN) or allocate: out of memory, said so.
      const std::string what = e.what();
      if (is_out_of_memory(e) || message_says_out_of_memory(what)) {
        throw RuntimeError(p + ": out of memory writing the OpenEXR file (" + what + ")");
      }
      throw RuntimeError(p + ": cannot write OpenEXR file: " + e.what());
    }
  }, opts.group);
}

// ---------------------------------------------------------------------------------------------
// Reading

namespace {

struct LayerChannels {
  std::vector<std::pair<double, std::string>> channels;  // (λ nm, full channel name), sorted by λ
  std::vector<double> lambdas() const {
    std::vector<double> out;
    for (const auto& c : channels) out.push_back(c.first);
    return out;
  }
};

// OpenEXR 3.1's Imf::Header trusts the sizes a header declares and allocates them before it finds
// the bytes missing: an 865-byte file whose string attribute declares 1.9 GB, found by
// fuzz_spectral_exr. It reads a value of a fixed-size type (box2i, int, ...) by its type, a channel
// list up to its empty name, a preview by its width × height, a string vector string by string, and
// anything else (strings, float vectors, unknown types as opaque bytes) by the declared size; when
// these disagree it reads the rest of the header out of step (a second fuzz find: a channel list
// ending early, after which a pixel-data byte pair was read as a 1.9 GB string size). The walk below
// reads the header(s) the same way (name, type name, int32 size, value; an empty name ends a header;
// a multi-part file ends its list of headers with an empty one) and refuses a value whose content
// disagrees with its declared size (no valid writer makes one) and any size larger than the bytes
// that hold it. Anything else malformed is left for OpenEXR to report.
std::int64_t le_u32(const char* b) {
  const auto* u = reinterpret_cast<const unsigned char*>(b);
  return std::int64_t{u[0]} | std::int64_t{u[1]} << 8 | std::int64_t{u[2]} << 16 | std::int64_t{u[3]} << 24;
}
std::int64_t le_i32(const char* b) { return static_cast<std::int32_t>(static_cast<std::uint32_t>(le_u32(b))); }

// The value size of OpenEXR 3.1's fixed-size attribute types; -1 for the others.
int fixed_value_size(const std::string& type) {
  static const std::map<std::string, int> sizes = {
      {"box2f", 16},   {"box2i", 16},   {"chromaticities", 32}, {"compression", 1}, {"deepImageState", 1},
      {"double", 8},   {"envmap", 1},   {"float", 4},           {"int", 4},         {"keycode", 28},
      {"lineOrder", 1}, {"m33d", 72},   {"m33f", 36},           {"m44d", 128},      {"m44f", 64},
      {"rational", 8}, {"tiledesc", 9}, {"timecode", 8},        {"v2d", 16},        {"v2f", 8},
      {"v2i", 8},      {"v3d", 24},     {"v3f", 12},            {"v3i", 12}};
  const auto it = sizes.find(type);
  return it == sizes.end() ? -1 : it->second;
}

// For the types OpenEXR reads by their content: empty when the content fills the value exactly.
std::string content_problem(const std::string& type, const std::string& v) {
  const auto n = static_cast<std::int64_t>(v.size());
  if (type == "chlist") {  // (name, 16 bytes)*, empty name
    for (std::size_t at = 0; at < v.size();) {
      const auto end = v.find('\0', at);
      if (end == std::string::npos) break;
      if (end == at) return end + 1 == v.size() ? "" : "is a channel list that ends before its size";
      at = end + 1 + 16;
    }
    return "is a channel list that runs past its size";
  }
  if (type == "stringvector") {  // (int32 length, bytes)*
    std::int64_t at = 0;
    for (; at + 4 <= n;) {
      const std::int64_t len = le_i32(v.data() + at);
      if (len < 0 || len > n - at - 4) return "holds a string of " + std::to_string(len) + " bytes";
      at += 4 + len;
    }
    return at == n ? "" : "is a string vector that runs past its size";
  }
  if (type == "preview") {  // uint32 width, uint32 height, 4 bytes per pixel
    if (n < 8) return "is a preview image without its size";
    const std::int64_t w = le_u32(v.data()), h = le_u32(v.data() + 4), bytes = n - 8;
    if ((w > 0 && h > 0 && w > bytes / 4 / h) || w * h * 4 != bytes) {
      return "holds a " + std::to_string(w) + "x" + std::to_string(h) + " preview image";
    }
  }
  return {};
}

void check_header_sizes(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  in.seekg(0, std::ios::end);
  const std::int64_t file_size = static_cast<std::int64_t>(in.tellg());
  in.seekg(0);
  char magic_version[8];
  if (!in.read(magic_version, sizeof magic_version)) return;
  const bool multipart = (le_u32(magic_version + 4) & 0x1000) != 0;
  // Reads a null-terminated name; false at end of file or when it is too long to be a name.
  const auto read_name = [&in](std::string& out) {
    out.clear();
    for (char c; in.get(c);) {
      if (c == '\0') return true;
      if (out.size() == 255) return false;
      out.push_back(c);
    }
    return false;
  };
  std::string name, type, value;
  while (true) {
    int attributes = 0;
    while (read_name(name) && !name.empty()) {
      ++attributes;
      char size_bytes[4];
      if (!read_name(type) || !in.read(size_bytes, sizeof size_bytes)) return;
      const std::int64_t size = le_i32(size_bytes);
      const std::int64_t left = file_size - static_cast<std::int64_t>(in.tellg());
      const auto refuse = [&](const std::string& what) {
        throw InputError(p, "header attribute \"" + detail::printable(name) + "\" (" + detail::printable(type) + ", " +
                                std::to_string(size) + " bytes) " + what + " (damaged file?)");
      };
      if (size < 0 || size > left) refuse("is larger than the " + std::to_string(left) + " bytes left in the file");
      const int fixed = fixed_value_size(type);
      if (fixed >= 0 && size != fixed) refuse("should have " + std::to_string(fixed) + " bytes");
      if (type == "floatvector" && size % 4 != 0) refuse("is not a whole number of floats");
      if (type == "chlist" || type == "stringvector" || type == "preview") {
        value.resize(static_cast<std::size_t>(size));
        if (!in.read(value.data(), size)) return;
        if (const std::string problem = content_problem(type, value); !problem.empty()) refuse(problem);
      } else {
        in.seekg(size, std::ios::cur);
      }
    }
    if (!in || !multipart || attributes == 0) return;
  }
}

const std::string* find_string_attr(const Imf::Header& h, const char* name) {
  const auto* a = h.findTypedAttribute<Imf::StringAttribute>(name);
  return a ? &a->value() : nullptr;
}

std::int64_t int_attr(const Imf::Header& h, const char* name, const std::string& path) {
  if (const auto* a = h.findTypedAttribute<Imf::IntAttribute>(name)) return a->value();
  if (const auto* s = find_string_attr(h, name)) {
    std::int64_t v = 0;
    const auto res = std::from_chars(s->data(), s->data() + s->size(), v);
    if (res.ec != std::errc() || res.ptr != s->data() + s->size()) {
      throw InputError(path, std::string(name) + ": \"" + *s + "\" is not an integer");
    }
    return v;
  }
  return 0;
}

// prizma:seed as put_seed writes it. A negative value (an int or a string) is a file written before
// 0.3, which stored the 64-bit seed as a signed number: seed − 2^64 for seeds from 2^63 on.
std::uint64_t read_seed(const Imf::Header& h, const char* name, const std::string& path) {
  if (const auto* a = h.findTypedAttribute<Imf::IntAttribute>(name)) {
    return static_cast<std::uint64_t>(static_cast<std::int64_t>(a->value()));
  }
  const auto* s = find_string_attr(h, name);
  if (s == nullptr) return 0;
  const char* begin = s->data();
  const char* end = s->data() + s->size();
  if (!s->empty() && s->front() == '-') {
    std::int64_t v = 0;
    const auto res = std::from_chars(begin, end, v);
    if (res.ec == std::errc() && res.ptr == end) return static_cast<std::uint64_t>(v);
  } else {
    std::uint64_t v = 0;
    const auto res = std::from_chars(begin, end, v);
    if (res.ec == std::errc() && res.ptr == end) return v;
  }
  throw InputError(path, std::string(name) + ": \"" + *s + "\" is not a 64-bit seed");
}

std::string describe_lambdas(const std::vector<double>& l) {
  std::ostringstream os;
  os << l.size() << " channels";
  if (!l.empty()) os << " " << l.front() << "–" << l.back() << " nm";
  return os.str();
}

// Reads one layer's channels into a pixel-major, bin-contiguous buffer.
// prizma:binEdgesNm in any numeric form OpenEXR holds: Prizma writes a float vector, but
// OpenImageIO (oiiotool) rewrites a float array of 2, 3, 9 or 16 values as v2f, v3f, m33f or
// m44f, and other tools may write doubles. Empty when absent; InputError for any other type.
std::optional<std::vector<double>> edges_attribute(const Imf::Header& h, const char* name, const std::string& p) {
  const auto it = h.find(name);
  if (it == h.end()) return std::nullopt;
  const Imf::Attribute* attr = &it.attribute();
  std::vector<double> v;
  auto take = [&](const auto* values, std::size_t n) { v.assign(values, values + n); };
  if (const auto* a = dynamic_cast<const Imf::FloatVectorAttribute*>(attr)) take(a->value().data(), a->value().size());
  else if (const auto* a2f = dynamic_cast<const Imf::V2fAttribute*>(attr)) take(&a2f->value()[0], 2);
  else if (const auto* a3f = dynamic_cast<const Imf::V3fAttribute*>(attr)) take(&a3f->value()[0], 3);
  else if (const auto* m3f = dynamic_cast<const Imf::M33fAttribute*>(attr)) take(&m3f->value()[0][0], 9);
  else if (const auto* m4f = dynamic_cast<const Imf::M44fAttribute*>(attr)) take(&m4f->value()[0][0], 16);
  else if (const auto* a2d = dynamic_cast<const Imf::V2dAttribute*>(attr)) take(&a2d->value()[0], 2);
  else if (const auto* a3d = dynamic_cast<const Imf::V3dAttribute*>(attr)) take(&a3d->value()[0], 3);
  else if (const auto* m3d = dynamic_cast<const Imf::M33dAttribute*>(attr)) take(&m3d->value()[0][0], 9);
  else if (const auto* m4d = dynamic_cast<const Imf::M44dAttribute*>(attr)) take(&m4d->value()[0][0], 16);
  else if (const auto* f = dynamic_cast<const Imf::FloatAttribute*>(attr)) v = {f->value()};
  else if (const auto* d = dynamic_cast<const Imf::DoubleAttribute*>(attr)) v = {d->value()};
  else {
    throw InputError(p, std::string(name) + " has type " + attr->typeName() +
                            "; expected the bin edges as floats (floatvector, v2f, v3f, m33f, m44f or doubles)");
  }
  return v;
}

void add_slices(Imf::FrameBuffer& fb, const LayerChannels& layer, std::vector<float>& dest,
                const Imath::Box2i& dw, int bins) {
  const std::size_t x_stride = sizeof(float) * static_cast<std::size_t>(bins);
  const std::size_t y_stride = x_stride * static_cast<std::size_t>(dw.max.x - dw.min.x + 1);
  for (int i = 0; i < bins; ++i) {
    fb.insert(layer.channels[static_cast<std::size_t>(i)].second,
              Imf::Slice::Make(Imf::FLOAT, dest.data() + i, dw, x_stride, y_stride));
  }
}

// What the header says about a file whose pixels do not match prizma:checksum: the signs that
// another tool re-encoded it (such tools copy prizma: attributes but not the exact values), or "".
std::string reencoding_signs(const Imf::Header& h) {
  std::vector<std::string> signs;
  const Imf::Compression c = h.compression();
  // Prizma writes small images uncompressed and larger ones with PIZ (earlier versions: PIZ at every
  // size, so PIZ is no sign).
  const bool small = prizma_compression(h) == Imf::NO_COMPRESSION;
  if (c != Imf::PIZ_COMPRESSION && (c != Imf::NO_COMPRESSION || !small)) {
    static const std::map<Imf::Compression, std::pair<const char*, bool>> kNames = {
        {Imf::NO_COMPRESSION, {"none", false}},  {Imf::RLE_COMPRESSION, {"RLE", false}},
        {Imf::ZIPS_COMPRESSION, {"ZIPS", false}}, {Imf::ZIP_COMPRESSION, {"ZIP", false}},
        {Imf::PXR24_COMPRESSION, {"PXR24", true}}, {Imf::B44_COMPRESSION, {"B44", true}},
        {Imf::B44A_COMPRESSION, {"B44A", true}},  {Imf::DWAA_COMPRESSION, {"DWAA", true}},
        {Imf::DWAB_COMPRESSION, {"DWAB", true}}};
    const auto it = kNames.find(c);
    const std::string name = it == kNames.end() ? "unknown" : it->second.first;
    const bool lossy = it != kNames.end() && it->second.second;
    signs.push_back(std::string("its compression is ") + (lossy ? "the lossy " : "") + name +
                    (small ? ", Prizma writes an image this small uncompressed" : ", Prizma writes PIZ"));
  }
  bool any_half = false, any_float = false;
  for (auto it = h.channels().begin(); it != h.channels().end(); ++it) {
    // Coefficient channels are half in every Prizma file (float in files of 2026-12-01), whatever the bins'.
    if (detail::CoefficientChannel cc; detail::parse_coefficient_channel(it.name(), cc)) continue;
    (it.channel().type == Imf::HALF ? any_half : any_float) = true;
  }
  if (any_half && any_float) signs.push_back("it mixes half and float channels");
  if (const auto* sw = h.findTypedAttribute<Imf::StringAttribute>("Software")) {
    const std::string who = sw->value().substr(0, sw->value().find(" : "));
    signs.push_back("it was written by " + detail::printable(who.substr(0, 80)));
  }
  std::string out;
  for (const auto& s : signs) out += (out.empty() ? "" : "; ") + s;
  return out;
}

// prizma:checksum against the pixels read: v2 with the top-level layer `top` (null when the file has
// none, or one light), v1 without it.
void verify_checksum(const std::string& p, const Imf::Header& header, const std::string& stored,
                     const SpectralImage& image, const std::vector<float>* top, const std::string& unverified_read) {
  std::string expected;
  if (stored.rfind(kChecksumScheme, 0) == 0) {
    std::uint64_t sum = light_layers_hash(image);
    if (top != nullptr) sum += detail::hash_float_bits(top->data(), top->size(), kFnvBasisSum);
    sum += detail::reradiation_checksum(image);  // 0 without bispectral terms
    sum += detail::coefficients_checksum(image);  // 0 without spectral-basis coefficients
    expected = checksum_string(sum);
  } else if (stored.rfind(kChecksumSchemeV1, 0) == 0) {
    expected = checksum_string(light_layers_hash(image), kChecksumSchemeV1);
  } else {
    throw InputError(p, std::string(kAttrChecksum) + " \"" + stored + "\" is not of a known kind (expected " +
                            kChecksumScheme + "<16 hex digits>, or " + kChecksumSchemeV1 + "<16 hex digits> in older files)");
  }
  if (stored == expected) return;
  // Channels another tool left out (oiiotool --ch) are named, not taken for a re-encoding.
  if (const std::string missing = detail::missing_channels(image, top != nullptr, stored.rfind(kChecksumScheme, 0) == 0);
      !missing.empty()) {
    throw InputError(p, "pixel data do not match " + std::string(kAttrChecksum) + ": the file lacks " + missing +
                            ", which the checksum covers: another tool left them out (oiiotool --ch, say); " +
                            unverified_read + " reads what is there");
  }
  const std::string signs = reencoding_signs(header);
  if (signs.empty()) {
    throw InputError(p, "pixel data do not match " + std::string(kAttrChecksum) + " (the file is damaged; " +
                            unverified_read + " reads it anyway)");
  }
  throw InputError(p, "pixel data do not match " + std::string(kAttrChecksum) +
                          ": the file was probably re-encoded by another tool (" + signs +
                          "), which kept the attribute but not the exact values; " + unverified_read + " reads it");
}

}  // namespace

SpectralImage read_spectral_exr(const fs::path& path, const ExrReadOptions& opts) {
  const std::string p = path_string(path);
  require_regular_file(path, "an OpenEXR file");
  if (!Imf::isOpenExrFile(p.c_str())) throw InputError(p, "not an OpenEXR file");
  check_header_sizes(p);

  try {
    Imf::InputFile file(p.c_str(), io_threads());
    const Imf::Header& header = file.header();
    const Imath::Box2i dw = header.dataWindow();
    SpectralImage image;
    image.width = dw.max.x - dw.min.x + 1;
    image.height = dw.max.y - dw.min.y + 1;
    if (image.width <= 0 || image.height <= 0) throw InputError(p, "empty data window");

    // Classify the channels into layers.
    std::map<std::string, LayerChannels> layers;  // by layer prefix ("" = top level)
    bool any_emissive = false;
    std::vector<detail::ReradiationChannel> rerad_channels;  // bispectral T.<λin>.<λout>
    std::vector<detail::CoefficientChannel> coef_channels;   // spectral-basis [<light>.]coef.<j>
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
      if (detail::CoefficientChannel cc; detail::parse_coefficient_channel(it.name(), cc)) {
        coef_channels.push_back(std::move(cc));
        continue;
      }
      if (detail::ReradiationChannel rc; detail::parse_reradiation_channel(it.name(), p, rc)) {
        rerad_channels.push_back(std::move(rc));
        continue;
      }
      const auto parsed = parse_channel_name(it.name(), p);
      if (!parsed) continue;
      if (parsed->emissive) {
        any_emissive = true;
        continue;
      }
      layers[parsed->layer].channels.emplace_back(parsed->lambda_nm, it.name());
    }
    // Compact: coefficients and no bins (prizma-relight compress --compact).
    const bool compact = layers.empty() && !coef_channels.empty();
    if (compact && !opts.allow_compact) {
      throw InputError(p, "compact file: it holds spectral-basis coefficients per pixel and light (prizma-relight compress "
                          "--compact), not the transport bins; only prizma-relight relights it (from the coefficients)");
    }
    if (compact && !rerad_channels.empty()) throw InputError(p, "compact file with bispectral channels");
    if (layers.empty() && !compact) {
      if (any_emissive) {
        throw InputError(p, "emissive-only spectral EXR (S0..S3 channels): Prizma reads reflective T.<λ>nm "
                            "channels only");
      }
      throw InputError(p, "no spectral channels (expected T.<wavelength>nm channels, e.g. T.550,000000nm)");
    }
    for (auto& [name, layer] : layers) {
      std::sort(layer.channels.begin(), layer.channels.end());
      for (std::size_t i = 1; i < layer.channels.size(); ++i) {
        if (layer.channels[i].first == layer.channels[i - 1].first) {
          throw InputError(p, "channels \"" + layer.channels[i - 1].second + "\" and \"" + layer.channels[i].second +
                                  "\" have the same wavelength");
        }
      }
    }

    // Attributes.
    SpectralExrInfo& info = image.info;
    for (auto it = header.begin(); it != header.end(); ++it) {
      if (std::string_view(it.name()).rfind("prizma:", 0) == 0) info.is_prizma = true;
    }
    if (const auto* s = find_string_attr(header, kAttrLights)) info.light_records = parse_light_records(*s, p + ": " + kAttrLights);
    if (const auto* s = find_string_attr(header, kAttrSampleRange)) info.sample_range = *s;
    if (const auto* s = find_string_attr(header, kAttrSceneHash)) info.scene_hash = *s;
    if (const auto* s = find_string_attr(header, kAttrVersion)) info.version = *s;
    if (const auto* s = find_string_attr(header, kAttrWavelengthSampling)) info.wavelength_sampling = *s;
    if (const auto* s = find_string_attr(header, kAttrScenePath)) info.scene_path = *s;
    if (const auto* s = find_string_attr(header, kAttrRenderOptions)) info.render_options = *s;
    info.samples = int_attr(header, kAttrSamples, p);
    info.seed = read_seed(header, kAttrSeed, p);

    // Light layers: named layers (not variance) if any, else the top-level layer.
    auto is_variance = [](const std::string& layer) {
      return layer == kVarianceLayer || (layer.size() > 4 && layer.compare(layer.size() - 4, 4, ".var") == 0);
    };
    std::vector<std::string> light_layers;
    std::set<std::string> compact_layers;  // a compact file: the coefficient channels' layers
    for (const auto& c : coef_channels) compact_layers.insert(c.layer);
    if (compact && compact_layers.size() > 1) compact_layers.erase("");
    for (const auto& name : compact ? std::vector<std::string>(compact_layers.begin(), compact_layers.end())
                                    : std::vector<std::string>()) {
      if (name.empty()) continue;
      if (!valid_light_name(name)) {
        throw InputError(p, "layer \"" + name + "\" is not a valid light name (letters, digits, '_' and '-')");
      }
      light_layers.push_back(name);
    }
    for (const auto& [name, layer] : layers) {
      if (name.empty() || is_variance(name)) continue;
      if (!valid_light_name(name)) {
        throw InputError(p, "layer \"" + name + "\" is not a valid light name (letters, digits, '_' and '-')");
      }
      light_layers.push_back(name);
    }
    // JSON order of the lights when it names exactly these layers (the file's channels are sorted).
    std::vector<std::string> json_names;
    for (const LightRecord& r : info.light_records) json_names.push_back(r.name);
    if (!light_layers.empty()) {
      std::vector<std::string> sorted_json = json_names;
      std::sort(sorted_json.begin(), sorted_json.end());
      if (sorted_json == light_layers) light_layers = json_names;
    }

    struct Source {
      std::string name;          // light name
      std::string layer;         // layer prefix in the file
      std::string variance;      // variance layer prefix, or empty
    };
    std::vector<Source> sources;
    if (!light_layers.empty()) {
      for (const auto& l : light_layers) {
        sources.push_back({l, l, layers.count(l + ".var") ? l + ".var" : std::string()});
      }
    } else {
      if (!layers.count("") && !compact) {
        throw InputError(p, "only variance layers, no spectral T.<wavelength>nm layer");
      }
      std::string name = "default";
      if (json_names.size() == 1 && valid_light_name(json_names.front())) name = json_names.front();
      sources.push_back({name, "", layers.count(kVarianceLayer) ? std::string(kVarianceLayer) : std::string()});
    }
    {
      std::vector<std::string> names;
      for (const auto& s : sources) names.push_back(s.name);
      check_light_records(info.light_records, names, p);
    }

    // Every light (and the top level and variance layers) must carry the same wavelengths.
    const std::vector<double> lambdas = compact ? std::vector<double>() : layers.at(sources.front().layer).lambdas();
    auto check_same = [&](const std::string& layer, const std::string& what) {
      const auto other = layers.at(layer).lambdas();
      if (other != lambdas) {
        throw InputError(p, what + " has " + describe_lambdas(other) + ", but layer \"" + sources.front().layer +
                                "\" has " + describe_lambdas(lambdas) + ": light layers must share their channels");
      }
    };
    for (const auto& s : sources) {
      if (compact) break;
      check_same(s.layer, s.layer.empty() ? "the top-level layer" : "layer \"" + s.layer + "\"");
      if (!s.variance.empty()) check_same(s.variance, "variance layer \"" + s.variance + "\"");
    }
    if (!light_layers.empty() && layers.count("")) check_same("", "the top-level layer");
    int n = static_cast<int>(lambdas.size());

    // Bin edges: prizma:binEdgesNm (checked against the centres), else midpoints between centres.
    // A compact file has no channels to check them against.
    std::vector<double> edges;
    if (const auto recorded = edges_attribute(header, kAttrEdges, p)) {
      const std::vector<double>& fe = *recorded;
      if (compact) {
        if (fe.size() < 2) throw InputError(p, std::string(kAttrEdges) + " has " + std::to_string(fe.size()) + " edges");
        n = static_cast<int>(fe.size()) - 1;
      }
      if (fe.size() != static_cast<std::size_t>(n) + 1) {
        throw InputError(p, std::string(kAttrEdges) + " has " + std::to_string(fe.size()) + " edges for " +
                                std::to_string(n) + " spectral channels (expected " + std::to_string(n + 1) + ")");
      }
      edges.assign(fe.begin(), fe.end());
      // The exact decimal copy, used only when it agrees with the float edges.
      if (const auto* s = find_string_attr(header, kAttrEdgesExact)) {
        std::vector<double> exact;
        for (auto tok : detail::split(*s, ' ')) {
          double v = 0.0;
          if (!detail::parse_double(tok, v)) break;
          exact.push_back(v);
        }
        bool agree = exact.size() == edges.size();
        for (std::size_t i = 0; agree && i < exact.size(); ++i) {
          agree = static_cast<float>(exact[i]) == static_cast<float>(fe[i]) || exact[i] == fe[i];
        }
        if (agree) edges = exact;
      }
      for (int i = 0; i < n && !compact; ++i) {
        if (!(lambdas[static_cast<std::size_t>(i)] > edges[static_cast<std::size_t>(i)] &&
              lambdas[static_cast<std::size_t>(i)] < edges[static_cast<std::size_t>(i) + 1])) {
          std::ostringstream os;
          os << "channel " << layers.at(sources.front().layer).channels[static_cast<std::size_t>(i)].second
             << " (centre " << lambdas[static_cast<std::size_t>(i)] << " nm) is not inside its bin ["
             << edges[static_cast<std::size_t>(i)] << ", " << edges[static_cast<std::size_t>(i) + 1] << "] nm of "
             << kAttrEdges;
          throw InputError(p, os.str());
        }
        // Prizma names each channel after its bin's centre (6 decimals); float edges are within
        // 4e-5 nm of the exact ones up to 830 nm.
        const double centre = 0.5 * (edges[static_cast<std::size_t>(i)] + edges[static_cast<std::size_t>(i) + 1]);
        if (!(std::abs(centre - lambdas[static_cast<std::size_t>(i)]) <= 1e-4)) {
          std::ostringstream os;
          os.precision(10);
          os << "channel " << layers.at(sources.front().layer).channels[static_cast<std::size_t>(i)].second << " ("
             << lambdas[static_cast<std::size_t>(i)] << " nm) is not the centre " << centre << " nm of its bin ["
             << edges[static_cast<std::size_t>(i)] << ", " << edges[static_cast<std::size_t>(i) + 1] << "] nm of "
             << kAttrEdges << ": the recorded edges disagree with the channels";
          throw InputError(p, os.str());
        }
      }
    } else {
      if (compact) throw InputError(p, "compact file without prizma:binEdgesNm: its bins are unknown");
      if (n < 2) throw InputError(p, "a single spectral channel without prizma:binEdgesNm gives no bin width");
      edges.resize(static_cast<std::size_t>(n) + 1);
      for (int i = 1; i < n; ++i) edges[i] = 0.5 * (lambdas[i - 1] + lambdas[i]);
      edges[0] = lambdas[0] - (edges[1] - lambdas[0]);
      edges[n] = lambdas[n - 1] + (lambdas[n - 1] - edges[n - 1]);
    }
    try {
      image.bins = BinLayout::from_edges(edges);
    } catch (const InputError& e) {
      throw InputError(p, "bin edges: " + e.reason());
    }

    // Pixels: one slice per channel, straight into each light's buffer.
    const std::size_t count = image.pixel_count() * static_cast<std::size_t>(n);
    Imf::FrameBuffer fb;
    for (const auto& s : sources) {
      TransportLayer& light = image.lights.emplace_back();
      light.name = s.name;
    }
    for (std::size_t k = 0; k < sources.size() && !compact; ++k) {
      TransportLayer& light = image.lights[k];
      light.data.assign(count, 0.0f);
      add_slices(fb, layers.at(sources[k].layer), light.data, dw, n);
      if (!sources[k].variance.empty()) {
        light.variance.assign(count, 0.0f);
        add_slices(fb, layers.at(sources[k].variance), light.variance, dw, n);
      }
    }
    {
      std::vector<std::string> light_prefixes;
      for (const auto& s : sources) light_prefixes.push_back(s.layer);
      detail::add_reradiation_for_read(rerad_channels, light_prefixes, lambdas, image, fb, dw, p);
    }
    // The top-level T layer of a file with named light layers, read only to verify it (checksum v2).
    const std::string* stored = opts.verify_checksum ? find_string_attr(header, kAttrChecksum) : nullptr;
    // Spectral-basis coefficients: kept with read_coefficients (always in a compact file), else read
    // only to verify the checksum.
    const bool keep_coefficients = opts.read_coefficients || compact;
    if (keep_coefficients || stored != nullptr) {
      std::vector<std::string> light_prefixes;
      for (const auto& s : sources) light_prefixes.push_back(s.layer);
      detail::add_coefficients_for_read(coef_channels, header, light_prefixes, n, image, fb, dw, p);
    }
    std::vector<float> top;
    const bool read_top = stored != nullptr && stored->rfind(kChecksumScheme, 0) == 0 && !light_layers.empty() &&
                          layers.count("") != 0;
    if (read_top) {
      top.assign(count, 0.0f);
      add_slices(fb, layers.at(""), top, dw, n);
    }
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);

    // A file written with a checksum must give back exactly what was written: PIZ has no check of
    // its own, so a damaged but complete file could otherwise read as other, finite values.
    if (stored != nullptr) verify_checksum(p, header, *stored, image, read_top ? &top : nullptr, opts.unverified_read);
    detail::check_coefficients_finite(image, p);
    if (!keep_coefficients) {
      for (auto& light : image.lights) light.coefficients = LayerCoefficients{};
      image.coefficient_criterion.clear();
    }
    for (std::size_t k = 0; k < sources.size(); ++k) {
      const std::string what = sources[k].layer.empty() ? "layer T" : "layer \"" + sources[k].layer + "\"";
      check_finite(image.lights[k].data, image.width, n, what, p);
      if (!sources[k].variance.empty()) {
        check_finite(image.lights[k].variance, image.width, n, "layer \"" + sources[k].variance + "\"", p);
      }
    }
    detail::check_reradiation_finite(image, p);
    return image;
  } catch (const InputError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw RuntimeError(p + ": out of memory reading the file's header and pixels");
  } catch (const std::system_error& e) {
    if (is_out_of_resources(e)) throw RuntimeError(p + ": out of memory starting OpenEXR's threads (" + e.what() + ")");
    throw InputError(p, std::string("cannot read OpenEXR file (truncated or corrupt?): ") + e.what());
  } catch (const std::exception& e) {
    // OpenEXR (Iex) exceptions: truncated or corrupt files. Its worker threads report a failed
    // allocation as an Iex message ("Out of memory", "std::bad_alloc"): that is not the file's fault.
    // The message quotes channel names from the file, which may spell those words themselves.
    const std::string what = e.what();
    if (message_says_out_of_memory(what)) {
      throw RuntimeError(p + ": out of memory reading the pixels (" + what + ")");
    }
    throw InputError(p, std::string("cannot read OpenEXR file (truncated or corrupt?): ") + e.what());
  }
}

}  // namespace prizma::spectral
