// write_spectral_exr (docs/spectral-exr.md): the image validated, its layers as channels (per-bin
// layers here; bispectral terms and coefficients by their own parts, bispectral.cpp and
// coefficients_exr.cpp), the attributes (exr/attributes.cpp), the checksum (exr/checksum.cpp), then
// one atomic write.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <half.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <list>
#include <set>
#include <string>
#include <vector>

#include "bispectral_exr.h"
#include "coefficients_exr.h"
#include "guides_exr.h"
#include "exr/attributes.h"
#include "exr/checksum.h"
#include "exr/exr_common.h"
#include "prizma/spectral/atomic_file.h"
#include "prizma/spectral/bispectral.h"
#include "prizma/spectral/colour.h"
#include "prizma/spectral/colour_matching.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/light_spectrum.h"
#include "prizma/spectral/output_group.h"
#include "prizma/spectral/spectral_exr.h"
#include "prizma/spectral/out_of_memory.h"

namespace prizma::spectral {
namespace {

namespace fs = std::filesystem;
using exr::check_finite;
using exr::kAttrChecksum;
using exr::kHalfMax;
using exr::LayerKind;
using exr::sum_of_lights;

// One set of per-bin channels to write: a name prefix ("" / "key." / "var." / "key.var."), a
// pixel-major, bin-contiguous float buffer, its kind (the checksum term) and, for a half file, its
// values as half.
struct OutLayer {
  std::string prefix;
  const std::vector<float>* data;
  std::string what;  // for messages
  LayerKind kind;
  const std::vector<half>* half_data = nullptr;
};

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

// Sizes, names and finite values of the image's transport and variance layers.
void validate_image(const SpectralImage& image, const ExrWriteOptions& opts, const std::string& p) {
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
}

// The per-bin layers: the lights' transport (one light: top level; two or more, or bispectral terms:
// per light, and their sum at top level, held in `sum`) and their variance.
std::vector<OutLayer> bin_layers(const SpectralImage& image, const ExrWriteOptions& opts, std::vector<float>& sum,
                                 const std::string& p) {
  const int bins = image.bins.size();
  const bool multi = exr::has_named_layers(image);
  std::vector<OutLayer> layers;
  if (image.compact()) {
    // no transport layers
  } else if (multi) {
    sum = sum_of_lights(image);
    check_finite(sum, image.width, bins, "sum of all lights", p);
    layers.push_back({"", &sum, "sum of all lights", LayerKind::Sum});
    for (const auto& light : image.lights) {
      layers.push_back({light.name + ".", &light.data, "light \"" + light.name + "\"", LayerKind::Transport});
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
    layers.push_back({"", &light.data, "light \"" + light.name + "\"", LayerKind::Transport});
    if (opts.write_variance && !light.variance.empty()) {
      layers.push_back({"var.", &light.variance, "variance of light \"" + light.name + "\"", LayerKind::Variance});
    }
  }
  return layers;
}

// Half files: each layer's values as half (refused, or clamped with a warning, beyond half's range).
std::list<std::vector<half>> to_half(std::vector<OutLayer>& layers, std::size_t expected, const ExrWriteOptions& opts,
                                     const std::string& p) {
  std::list<std::vector<half>> half_buffers;
  std::size_t clamped = 0;
  for (auto& layer : layers) {
    auto& hb = half_buffers.emplace_back(expected);
    layer.half_data = &hb;
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
  return half_buffers;
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

// The per-bin layers' channels and slices: the slices point straight into the pixel-major,
// bin-contiguous buffers (bin i of pixel (x, y) at base + i, x stride = bins values, y stride =
// width·bins values). Returns the layers' checksum terms, of the values a reader gets back.
std::uint64_t add_bin_layers(const std::vector<OutLayer>& layers, const SpectralImage& image, Imf::PixelType type,
                             Imf::Header& header, Imf::FrameBuffer& fb) {
  const int bins = image.bins.size();
  const std::size_t expected = image.pixel_count() * static_cast<std::size_t>(bins);
  std::vector<std::string> suffixes;
  for (int i = 0; i < bins; ++i) suffixes.push_back(spectral_channel_name(image.bins.centre_nm(i)));
  const bool half_out = type == Imf::HALF;
  const std::size_t elem = half_out ? sizeof(half) : sizeof(float);
  const std::size_t x_stride = elem * static_cast<std::size_t>(bins);
  const std::size_t y_stride = x_stride * static_cast<std::size_t>(image.width);
  std::uint64_t checksum = 0;
  for (const auto& layer : layers) {
    checksum += half_out ? exr::layer_hash(layer.kind, layer.half_data->data(), expected)
                         : exr::layer_hash(layer.kind, layer.data->data(), expected);
    const char* base = half_out ? reinterpret_cast<const char*>(layer.half_data->data())
                                : reinterpret_cast<const char*>(layer.data->data());
    for (int i = 0; i < bins; ++i) {
      header.channels().insert(layer.prefix + suffixes[i], Imf::Channel(type));
      fb.insert(layer.prefix + suffixes[i],
                Imf::Slice(type, const_cast<char*>(base + elem * static_cast<std::size_t>(i)), x_stride, y_stride));
    }
  }
  return checksum;
}

// Preview channels R, G, B (derived from the layers, so outside the checksum; half files clamp them
// to half's range): their buffers, whose slices point into them.
struct PreviewChannels {
  std::vector<float> rgb;
  std::vector<half> rgb_half;
};
void add_preview(PreviewChannels& preview, const SpectralImage& image, Imf::PixelType type, Imf::Header& header,
                 Imf::FrameBuffer& fb) {
  preview.rgb = preview_rgb(image);
  if (preview.rgb.empty()) return;
  const bool half_out = type == Imf::HALF;
  if (half_out) {
    for (const float v : preview.rgb) preview.rgb_half.emplace_back(std::clamp(v, -kHalfMax, kHalfMax));
  }
  const char* base = half_out ? reinterpret_cast<const char*>(preview.rgb_half.data())
                              : reinterpret_cast<const char*>(preview.rgb.data());
  const std::size_t elem = half_out ? sizeof(half) : sizeof(float);
  const std::size_t stride = 3 * elem;
  for (std::size_t c = 0; c < 3; ++c) {
    const char* name = c == 0 ? "R" : c == 1 ? "G" : "B";
    header.channels().insert(name, Imf::Channel(type));
    fb.insert(name, Imf::Slice(type, const_cast<char*>(base + elem * c), stride, stride * static_cast<std::size_t>(image.width)));
  }
}

// The write itself, atomically, with OpenEXR's thread count for the file's compression.
void write_file(const fs::path& path, const Imf::Header& header, const Imf::FrameBuffer& fb, int height,
                const ExrWriteOptions& opts, const std::string& p) {
  const bool compressed = header.compression() != Imf::NO_COMPRESSION;
  write_atomically(path, [&](AtomicOutput& out) {
    try {
      AtomicOStream stream(out);
      // OpenEXR's thread count: 0 encodes in this thread, n ≥ 1 keeps n chunks in flight on its pool.
      // Uncompressed chunks are only copied: no pool (starting its threads costs more than they save).
      int in_flight = 0;
      if (compressed && opts.threads != 1) in_flight = opts.threads > 1 ? std::min(opts.threads, exr::io_threads()) : exr::io_threads();
      Imf::OutputFile file(stream, header, in_flight);
      file.setFrameBuffer(fb);
      file.writePixels(height);
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

}  // namespace

void write_spectral_exr(const fs::path& path, const SpectralImage& image, const ExrWriteOptions& opts) {
  const std::string p = path.string();
  validate_image(image, opts, p);
  check_exr_bin_names(image.bins, p);  // every bin its own channel name
  std::vector<float> sum;               // the top-level sum of two or more lights
  std::vector<OutLayer> layers = bin_layers(image, opts, sum, p);
  const bool half_out = opts.pixel_type == ExrPixelType::Half;
  const std::list<std::vector<half>> half_layers =
      half_out ? to_half(layers, image.pixel_count() * static_cast<std::size_t>(image.bins.size()), opts, p)
               : std::list<std::vector<half>>();
  const Imf::PixelType type = half_out ? Imf::HALF : Imf::FLOAT;

  // Every kind of layer adds its channels, slices and checksum term; then the attributes.
  Imf::Header header(image.width, image.height);
  Imf::FrameBuffer fb;
  std::uint64_t checksum = add_bin_layers(layers, image, type, header, fb);
  const bool multi = exr::has_named_layers(image);
  detail::ReradiationBuffers rerad_buffers;  // bispectral terms (fluorescence; none for a diagonal image)
  checksum += detail::add_reradiation_for_write(image, multi, half_out, header, fb, rerad_buffers, p);
  std::list<std::vector<half>> coefficient_buffers;  // spectral-basis coefficients (half whatever the pixel type)
  checksum += detail::add_coefficients_for_write(image, multi, header, fb, p, coefficient_buffers);
  checksum += detail::add_guides_for_write(image, header, fb, p);  // float whatever the pixel type
  PreviewChannels preview;
  if (opts.write_preview) add_preview(preview, image, type, header, fb);
  exr::put_attributes(header, image, p);
  header.insert(kAttrChecksum, Imf::StringAttribute(exr::checksum_string(checksum)));

  // Compression, now that every channel is in the header: none for a small image, else PIZ (lossless
  // wavelet + Huffman: on noisy Monte Carlo float data it gave files ~25 % smaller than ZIP and wrote
  // about twice as fast; 512×512×32 floats: PIZ 23.7 MB, ZIP 31.4 MB, none 33.6 MB).
  header.compression() = exr::prizma_compression(header);
  write_file(path, header, fb, image.height, opts, p);
}

}  // namespace prizma::spectral
