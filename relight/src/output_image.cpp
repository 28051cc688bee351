#include "prizma/relight/output_image.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <memory>

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
  if (format == OutputFormat::Exr) spec.attributes.emplace_back("compression", "zip");
  if (format == OutputFormat::Jpeg) spec.attributes.emplace_back("Compression", "jpeg:95");
  for (const auto& [key, value] : metadata) spec.attributes.emplace_back(key, value);

  spectral::write_atomically(path, [&](spectral::AtomicOutput& out) {
    spectral::write_picture(out, spec, spectral::PicturePixelType::Float, pixels.data());
  });
}

}  // namespace prizma::relight
