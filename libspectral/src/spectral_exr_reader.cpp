// read_spectral_exr (docs/spectral-exr.md, "Reading"): the header guarded (exr/header_guard.cpp), the
// channels sorted into layers, the lights and their bins found, then the pixels of every kind of layer
// read in one pass and checked against prizma:checksum (exr/checksum.cpp).
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfTestFile.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "bispectral_exr.h"
#include "coefficients_exr.h"
#include "guides_exr.h"
#include "exr/attributes.h"
#include "exr/channel_names.h"
#include "exr/checksum.h"
#include "exr/exr_common.h"
#include "exr/header_guard.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/input_file.h"
#include "prizma/spectral/large_buffer.h"
#include "prizma/spectral/spectral_exr.h"
#include "prizma/spectral/out_of_memory.h"
#include "text_util.h"

namespace prizma::spectral {
namespace {

namespace fs = std::filesystem;
using exr::check_finite;
using exr::kAttrChecksum;
using exr::kAttrEdges;
using exr::kAttrEdgesExact;

// One layer's spectral channels: (λ nm, full channel name), sorted by λ.
struct LayerChannels {
  std::vector<std::pair<double, std::string>> channels;
  std::vector<double> lambdas() const {
    std::vector<double> out;
    for (const auto& c : channels) out.push_back(c.first);
    return out;
  }
};

// The header's channels by kind: spectral layers by prefix ("" = top level), bispectral and
// coefficient channels; a file of coefficients without bins is compact.
struct ChannelSets {
  std::map<std::string, LayerChannels> layers;
  std::vector<detail::ReradiationChannel> reradiation;  // [<light>.]T.<λin>.<λout>
  std::vector<detail::CoefficientChannel> coefficients;  // [<light>.]coef.<j>
  bool compact = false;
};

// Where light k's pixels are: its name, its layer prefix in the file and its variance layer's.
struct Source {
  std::string name;
  std::string layer;
  std::string variance;  // empty: none
};

ChannelSets classify_channels(const Imf::Header& header, const ExrReadOptions& opts, const std::string& p) {
  ChannelSets sets;
  bool any_emissive = false;
  for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
    if (detail::CoefficientChannel cc; detail::parse_coefficient_channel(it.name(), cc)) {
      sets.coefficients.push_back(std::move(cc));
      continue;
    }
    if (detail::ReradiationChannel rc; detail::parse_reradiation_channel(it.name(), p, rc)) {
      sets.reradiation.push_back(std::move(rc));
      continue;
    }
    const auto parsed = exr::parse_channel_name(it.name(), p);
    if (!parsed) continue;
    if (parsed->emissive) {
      any_emissive = true;
      continue;
    }
    sets.layers[parsed->layer].channels.emplace_back(parsed->lambda_nm, it.name());
  }
  // Compact: coefficients and no bins (prizma-relight compress --compact).
  sets.compact = sets.layers.empty() && !sets.coefficients.empty();
  if (sets.compact && !opts.allow_compact) {
    throw InputError(p, "compact file: it holds spectral-basis coefficients per pixel and light (prizma-relight compress "
                        "--compact), not the transport bins; only prizma-relight relights it (from the coefficients)");
  }
  if (sets.compact && !sets.reradiation.empty()) throw InputError(p, "compact file with bispectral channels");
  if (sets.layers.empty() && !sets.compact) {
    if (any_emissive) {
      throw InputError(p, "emissive-only spectral EXR (S0..S3 channels): Prizma reads reflective T.<λ>nm "
                          "channels only");
    }
    throw InputError(p, "no spectral channels (expected T.<wavelength>nm channels, e.g. T.550,000000nm)");
  }
  for (auto& [name, layer] : sets.layers) {
    std::sort(layer.channels.begin(), layer.channels.end());
    for (std::size_t i = 1; i < layer.channels.size(); ++i) {
      if (layer.channels[i].first == layer.channels[i - 1].first) {
        throw InputError(p, "channels \"" + layer.channels[i - 1].second + "\" and \"" + layer.channels[i].second +
                                "\" have the same wavelength");
      }
    }
  }
  return sets;
}

bool is_variance_layer(const std::string& layer) {
  return layer == exr::kVarianceLayer || (layer.size() > 4 && layer.compare(layer.size() - 4, 4, ".var") == 0);
}

// The named light layers (not variance), in the order of prizma:lights when it names exactly these
// layers (the file's channels are sorted), else alphabetical. A compact file: its coefficients' layers.
std::vector<std::string> named_light_layers(const ChannelSets& sets, const std::vector<LightRecord>& records,
                                            const std::string& p) {
  std::vector<std::string> names;
  auto add = [&](const std::string& name) {
    if (name.empty() || is_variance_layer(name)) return;
    if (!exr::valid_light_name(name)) {
      throw InputError(p, "layer \"" + name + "\" is not a valid light name (letters, digits, '_' and '-')");
    }
    names.push_back(name);
  };
  if (sets.compact) {
    std::set<std::string> compact_layers;
    for (const auto& c : sets.coefficients) compact_layers.insert(c.layer);
    for (const auto& name : compact_layers) add(name);
  }
  for (const auto& [name, layer] : sets.layers) add(name);
  std::vector<std::string> recorded;
  for (const LightRecord& r : records) recorded.push_back(r.name);
  std::vector<std::string> sorted = recorded;
  std::sort(sorted.begin(), sorted.end());
  if (!names.empty() && sorted == names) names = recorded;
  return names;
}

// Light layers: the named layers if any, else the top-level layer (named after the one record, or
// "default"). The records must describe them (check_light_records).
std::vector<Source> light_sources(const ChannelSets& sets, const std::vector<std::string>& named,
                                  const std::vector<LightRecord>& records, const std::string& p) {
  std::vector<Source> sources;
  if (!named.empty()) {
    for (const auto& l : named) sources.push_back({l, l, sets.layers.count(l + ".var") ? l + ".var" : std::string()});
  } else {
    if (!sets.layers.count("") && !sets.compact) throw InputError(p, "only variance layers, no spectral T.<wavelength>nm layer");
    std::string name = "default";
    if (records.size() == 1 && exr::valid_light_name(records.front().name)) name = records.front().name;
    sources.push_back({name, "", sets.layers.count(exr::kVarianceLayer) ? std::string(exr::kVarianceLayer) : std::string()});
  }
  std::vector<std::string> names;
  for (const auto& s : sources) names.push_back(s.name);
  check_light_records(records, names, p);
  return sources;
}

std::string describe_lambdas(const std::vector<double>& l) {
  std::ostringstream os;
  os << l.size() << " channels";
  if (!l.empty()) os << " " << l.front() << "–" << l.back() << " nm";
  return os.str();
}

// Every light (and the top level and variance layers) must carry the same wavelengths: those of the
// first light's layer, returned (none for a compact file).
std::vector<double> shared_lambdas(const ChannelSets& sets, const std::vector<Source>& sources, bool named,
                                   const std::string& p) {
  if (sets.compact) return {};
  const std::vector<double> lambdas = sets.layers.at(sources.front().layer).lambdas();
  auto check_same = [&](const std::string& layer, const std::string& what) {
    const auto other = sets.layers.at(layer).lambdas();
    if (other != lambdas) {
      throw InputError(p, what + " has " + describe_lambdas(other) + ", but layer \"" + sources.front().layer + "\" has " +
                              describe_lambdas(lambdas) + ": light layers must share their channels");
    }
  };
  for (const auto& s : sources) {
    check_same(s.layer, s.layer.empty() ? "the top-level layer" : "layer \"" + s.layer + "\"");
    if (!s.variance.empty()) check_same(s.variance, "variance layer \"" + s.variance + "\"");
  }
  if (named && sets.layers.count("")) check_same("", "the top-level layer");
  return lambdas;
}

// prizma:binEdgesNm's float edges, replaced by the exact decimal copy when that agrees with them.
std::vector<double> recorded_edges(const Imf::Header& header, const std::vector<double>& fe) {
  std::vector<double> edges(fe.begin(), fe.end());
  if (const auto* s = exr::find_string_attr(header, kAttrEdgesExact)) {
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
  return edges;
}

// Recorded edges must hold each channel's wavelength as their bin's centre (Prizma names each channel
// after its bin's centre, 6 decimals; float edges are within 4e-5 nm of the exact ones up to 830 nm).
void check_centres(const std::vector<double>& edges, const std::vector<double>& lambdas, const LayerChannels& first,
                   const std::string& p) {
  for (std::size_t i = 0; i < lambdas.size(); ++i) {
    const double lo = edges[i], hi = edges[i + 1], l = lambdas[i];
    if (!(l > lo && l < hi)) {
      std::ostringstream os;
      os << "channel " << first.channels[i].second << " (centre " << l << " nm) is not inside its bin [" << lo << ", "
         << hi << "] nm of " << kAttrEdges;
      throw InputError(p, os.str());
    }
    const double centre = 0.5 * (lo + hi);
    if (!(std::abs(centre - l) <= 1e-4)) {
      std::ostringstream os;
      os.precision(10);
      os << "channel " << first.channels[i].second << " (" << l << " nm) is not the centre " << centre
         << " nm of its bin [" << lo << ", " << hi << "] nm of " << kAttrEdges
         << ": the recorded edges disagree with the channels";
      throw InputError(p, os.str());
    }
  }
}

// Edges of a file without prizma:binEdgesNm: midpoints between the channels' wavelengths, the first
// and last bins mirrored about their channel. A mirrored outer edge past the colour matching tables
// (a file sampled at 400, 500, 600, 700 nm gives 350 nm) is clamped to them when its channel stays
// inside, and the clamp is noted (docs/spectral-exr.md, "Reading").
std::vector<double> inferred_edges(const std::vector<double>& lambdas, std::vector<std::string>& notes,
                                   const std::string& p) {
  const std::size_t n = lambdas.size();
  if (n < 2) throw InputError(p, "a single spectral channel without prizma:binEdgesNm gives no bin width");
  std::vector<double> edges(n + 1);
  for (std::size_t i = 1; i < n; ++i) edges[i] = 0.5 * (lambdas[i - 1] + lambdas[i]);
  edges[0] = lambdas[0] - (edges[1] - lambdas[0]);
  edges[n] = lambdas[n - 1] + (lambdas[n - 1] - edges[n - 1]);
  auto clamp_edge = [&](double& edge, double limit, double channel, bool low) {
    if (low ? !(edge < limit) : !(edge > limit)) return;
    if (low ? !(channel > limit) : !(channel < limit)) return;  // the channel itself outside: refused below
    std::ostringstream os;
    os << p << ": the inferred " << (low ? "first" : "last") << " bin edge " << edge << " nm is outside the colour matching"
       << " tables (" << BinLayout::kMinNm << "–" << BinLayout::kMaxNm << " nm): clamped to " << limit << " nm";
    notes.push_back(os.str());
    edge = limit;
  };
  clamp_edge(edges[0], BinLayout::kMinNm, lambdas[0], true);
  clamp_edge(edges[n], BinLayout::kMaxNm, lambdas[n - 1], false);
  return edges;
}

// The bins: prizma:binEdgesNm (checked against the centres), else inferred from the channels. A
// compact file has no channels to check them against (its bin count is the edges').
BinLayout bin_layout(const Imf::Header& header, const ChannelSets& sets, const std::vector<Source>& sources,
                     const std::vector<double>& lambdas, std::vector<std::string>& notes, const std::string& p) {
  std::vector<double> edges;
  if (const auto recorded = exr::edges_attribute(header, kAttrEdges, p)) {
    const std::vector<double>& fe = *recorded;
    if (sets.compact && fe.size() < 2) throw InputError(p, std::string(kAttrEdges) + " has " + std::to_string(fe.size()) + " edges");
    const std::size_t n = sets.compact ? fe.size() - 1 : lambdas.size();
    if (fe.size() != n + 1) {
      throw InputError(p, std::string(kAttrEdges) + " has " + std::to_string(fe.size()) + " edges for " + std::to_string(n) +
                              " spectral channels (expected " + std::to_string(n + 1) + ")");
    }
    edges = recorded_edges(header, fe);
    if (!sets.compact) check_centres(edges, lambdas, sets.layers.at(sources.front().layer), p);
  } else {
    if (sets.compact) throw InputError(p, "compact file without prizma:binEdgesNm: its bins are unknown");
    edges = inferred_edges(lambdas, notes, p);
  }
  try {
    return BinLayout::from_edges(edges);
  } catch (const InputError& e) {
    throw InputError(p, "bin edges: " + e.reason());
  }
}

// One layer's channels into a pixel-major, bin-contiguous buffer.
void add_slices(Imf::FrameBuffer& fb, const LayerChannels& layer, std::vector<float>& dest, const Imath::Box2i& dw,
                int bins) {
  const std::size_t x_stride = sizeof(float) * static_cast<std::size_t>(bins);
  const std::size_t y_stride = x_stride * static_cast<std::size_t>(dw.max.x - dw.min.x + 1);
  for (int i = 0; i < bins; ++i) {
    fb.insert(layer.channels[static_cast<std::size_t>(i)].second,
              Imf::Slice::Make(Imf::FLOAT, dest.data() + i, dw, x_stride, y_stride));
  }
}

// The pixels of every kind of layer in one read, checked against prizma:checksum, then for finite
// values. `image` has its size, bins and info.
void read_pixels(Imf::InputFile& file, const ChannelSets& sets, const std::vector<Source>& sources, bool named,
                 const std::vector<double>& lambdas, const ExrReadOptions& opts, SpectralImage& image,
                 const std::string& p) {
  const Imf::Header& header = file.header();
  const Imath::Box2i dw = header.dataWindow();
  const int n = image.bins.size();
  const std::size_t count = image.pixel_count() * static_cast<std::size_t>(n);
  Imf::FrameBuffer fb;
  std::vector<std::string> prefixes;
  for (const auto& s : sources) {
    TransportLayer& light = image.lights.emplace_back();
    light.name = s.name;
    prefixes.push_back(s.layer);
  }
  for (std::size_t k = 0; k < sources.size() && !sets.compact; ++k) {
    TransportLayer& light = image.lights[k];
    allocate_zeroed(light.data, count);
    add_slices(fb, sets.layers.at(sources[k].layer), light.data, dw, n);
    if (!sources[k].variance.empty()) {
      allocate_zeroed(light.variance, count);
      add_slices(fb, sets.layers.at(sources[k].variance), light.variance, dw, n);
    }
  }
  detail::add_reradiation_for_read(sets.reradiation, prefixes, lambdas, image, fb, dw, p);
  detail::add_guides_for_read(header, image, fb, dw, p);
  const std::string* stored = opts.verify_checksum ? exr::find_string_attr(header, kAttrChecksum) : nullptr;
  // Spectral-basis coefficients: kept with read_coefficients (always in a compact file), else read
  // only to verify the checksum.
  const bool keep_coefficients = opts.read_coefficients || sets.compact;
  if (keep_coefficients || stored != nullptr) {
    detail::add_coefficients_for_read(sets.coefficients, header, prefixes, n, image, fb, dw, p);
  }
  // The top-level T layer of a file with named light layers, read only to verify it (checksum v2).
  std::vector<float> top;
  const bool read_top = stored != nullptr && stored->rfind(exr::kChecksumScheme, 0) == 0 && named && sets.layers.count("") != 0;
  if (read_top) {
    allocate_zeroed(top, count);
    add_slices(fb, sets.layers.at(""), top, dw, n);
  }
  file.setFrameBuffer(fb);
  file.readPixels(dw.min.y, dw.max.y);

  // A file written with a checksum must give back exactly what was written: PIZ has no check of
  // its own, so a damaged but complete file could otherwise read as other, finite values.
  if (stored != nullptr) exr::verify_checksum(p, header, *stored, image, read_top ? &top : nullptr, opts.unverified_read);
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
  detail::check_guides_finite(image, p);
}

}  // namespace

SpectralImage read_spectral_exr(const fs::path& path, const ExrReadOptions& opts) {
  const std::string p = path.string();
  require_regular_file(path, "an OpenEXR file");
  if (!Imf::isOpenExrFile(p.c_str())) throw InputError(p, "not an OpenEXR file");
  exr::check_header_sizes(p);

  try {
    Imf::InputFile file(p.c_str(), exr::io_threads());
    const Imf::Header& header = file.header();
    const Imath::Box2i dw = header.dataWindow();
    SpectralImage image;
    image.width = dw.max.x - dw.min.x + 1;
    image.height = dw.max.y - dw.min.y + 1;
    if (image.width <= 0 || image.height <= 0) throw InputError(p, "empty data window");

    const ChannelSets sets = classify_channels(header, opts, p);
    image.info = exr::read_attributes(header, p);
    const std::vector<std::string> named = named_light_layers(sets, image.info.light_records, p);
    const std::vector<Source> sources = light_sources(sets, named, image.info.light_records, p);
    const std::vector<double> lambdas = shared_lambdas(sets, sources, !named.empty(), p);
    image.bins = bin_layout(header, sets, sources, lambdas, image.info.notes, p);
    read_pixels(file, sets, sources, !named.empty(), lambdas, opts, image, p);
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
