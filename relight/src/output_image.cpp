#include "prizma/relight/output_image.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include "prizma/spectral/atomic_file.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/image_io.h"

namespace prizma::relight {

namespace fs = std::filesystem;
using spectral::InputError;

OutputFormat output_format_for(const fs::path& path, const std::string& input) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".png") return OutputFormat::Png;
  if (ext == ".tif" || ext == ".tiff") return OutputFormat::Tiff;
  if (ext == ".exr") return OutputFormat::Exr;
  if (ext == ".jpg" || ext == ".jpeg") return OutputFormat::Jpeg;
  throw InputError(input, "unknown output format \"" + path.string() + "\" (known: .png, .tif, .tiff, .jpg, .jpeg, .exr)");
}

void check_output_path(const fs::path& path, const std::string& input) {
  output_format_for(path, input);
  spectral::check_output_file(path, input);
}

bool needs_transform(OutputFormat format, const OutputOptions& opts) {
  return format != OutputFormat::Exr || !opts.display.colour_space.empty();
}

spectral::DisplayOptions transform_options(OutputFormat format, const OutputOptions& opts) {
  spectral::DisplayOptions d = opts.display;
  if (format != OutputFormat::Exr) d.colour_space.clear();
  return d;
}

void check_output_options(OutputFormat format, const OutputOptions& opts) {
  if (opts.bit_depth != 8 && opts.bit_depth != 16) {
    throw InputError("--bit-depth", "must be 8 or 16, not " + std::to_string(opts.bit_depth));
  }
  if (format == OutputFormat::Jpeg && opts.bit_depth != 8) {
    throw InputError("--bit-depth", "JPEG is 8-bit only (got " + std::to_string(opts.bit_depth) + "; use .png or .tif for 16)");
  }
  if (needs_transform(format, opts)) spectral::DisplayTransform check(transform_options(format, opts));
}

std::vector<float> to_display(const XyzImage& image, const spectral::DisplayTransform& display) {
  std::vector<float> rgb(image.xyz);
  for (float& v : rgb)
    if (!std::isfinite(v)) v = 0.0f;
  display.apply(rgb.data(), image.pixel_count());
  return rgb;
}

namespace {

// The EXR "chromaticities" (red, green, blue, white xy) of an EXR output: XYZ's own for XYZ; for a
// linear colour space those that take its RGB back to the image's XYZ (the OCIO transform's matrix M,
// found from the XYZ unit vectors: the columns of M⁻¹ are the primaries' XYZ, M⁻¹·(1, 1, 1) the
// white's). Nothing for a colour space that is not linear.
std::optional<std::array<float, 8>> exr_chromaticities(const OutputOptions& opts) {
  if (opts.display.colour_space.empty()) return std::array<float, 8>{1, 0, 0, 1, 0, 0, 1.0f / 3, 1.0f / 3};
  const spectral::DisplayTransform transform(transform_options(OutputFormat::Exr, opts));
  std::array<float, 9> unit{1, 0, 0, 0, 1, 0, 0, 0, 1}, half{0.5f, 0, 0, 0, 0.5f, 0, 0, 0, 0.5f};
  transform.apply(unit.data(), 3);
  transform.apply(half.data(), 3);
  Eigen::Matrix3d m;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) {
      m(r, c) = unit[static_cast<std::size_t>(3 * c + r)];
      const double h = half[static_cast<std::size_t>(3 * c + r)];
      if (!(std::abs(2.0 * h - m(r, c)) <= 1e-5 * (1.0 + std::abs(m(r, c))))) return std::nullopt;  // not linear
    }
  if (!(std::abs(m.determinant()) > 1e-12)) return std::nullopt;
  const Eigen::Matrix3d inv = m.inverse();
  std::array<float, 8> out{};
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d xyz = k < 3 ? Eigen::Vector3d(inv.col(k)) : Eigen::Vector3d(inv * Eigen::Vector3d::Ones());
    const double sum = xyz.sum();
    if (!(std::abs(sum) > 1e-12)) return std::nullopt;
    out[static_cast<std::size_t>(2 * k)] = static_cast<float>(xyz[0] / sum);
    out[static_cast<std::size_t>(2 * k + 1)] = static_cast<float>(xyz[1] / sum);
  }
  return out;
}

}  // namespace

void write_output_image(const fs::path& path, const XyzImage& image, const OutputOptions& opts,
                        const ImageMetadata& metadata) {
  const OutputFormat format = output_format_for(path);
  check_output_path(path);
  check_output_options(format, opts);

  // Pixels: linear XYZ / colour space for EXR, display-encoded and clamped to [0, 1] otherwise.
  std::vector<float> pixels;
  if (needs_transform(format, opts)) {
    const spectral::DisplayTransform transform(transform_options(format, opts));
    pixels = to_display(image, transform);
  } else {
    pixels = image.xyz;
    for (float& v : pixels)
      if (!std::isfinite(v)) v = 0.0f;
  }
  spectral::PictureSpec spec;
  spec.width = image.width;
  spec.height = image.height;
  spec.stored = spectral::PicturePixelType::Float;
  if (format != OutputFormat::Exr) {
    for (float& v : pixels) v = std::clamp(v, 0.0f, 1.0f);
    spec.stored = opts.bit_depth == 16 ? spectral::PicturePixelType::UInt16 : spectral::PicturePixelType::UInt8;
  }
  if (format == OutputFormat::Exr && opts.display.colour_space.empty()) {
    spec.channel_names = {"X", "Y", "Z"};
  } else {
    spec.channel_names = {"R", "G", "B"};
  }
  if (format == OutputFormat::Exr) {
    spec.attributes.emplace_back("compression", "zip");
    if (const auto chromaticities = exr_chromaticities(opts)) {
      spec.float_attributes.emplace_back("chromaticities", std::vector<float>(chromaticities->begin(), chromaticities->end()));
    }
  } else if (format == OutputFormat::Png) {
    // The display it is encoded for (OpenImageIO writes the sRGB chunk for "sRGB"). Not for TIFF:
    // OpenImageIO 2.4's TIFF writer then leaves a file without its ImageLength field.
    spec.attributes.emplace_back("oiio:ColorSpace", opts.display.display);
  } else if (format == OutputFormat::Jpeg) {
    spec.attributes.emplace_back("Compression", "jpeg:95");
  }
  for (const auto& [key, value] : metadata) spec.attributes.emplace_back(key, value);

  spectral::write_atomically(path, [&](spectral::AtomicOutput& out) {
    spectral::write_picture(out, spec, spectral::PicturePixelType::Float, pixels.data());
  });
}

}  // namespace prizma::relight
