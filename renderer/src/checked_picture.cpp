#include "checked_picture.h"

#include <algorithm>
#include <memory>
#include <system_error>

#include "prizma/spectral/error.h"
#include "prizma/spectral/image_io.h"
#include "prizma/spectral/input_file.h"
#include "prizma/spectral/stderr_capture.h"

namespace prizma::render {

using spectral::InputError;

CheckedPicture read_picture_checked(const std::filesystem::path& path, const PictureLimits& limits,
                                    const std::string& input) {
  const std::string file = path.string();
  try {
    spectral::require_regular_file(path, limits.kind);
  } catch (const InputError& e) {
    throw InputError(input, std::string("image ") + e.what());
  }
  std::error_code ec;
  const auto file_bytes = static_cast<long long>(std::filesystem::file_size(path, ec));
  // libpng and OpenEXR may print their errors on stderr before OpenImageIO reports them (the image
  // module, loaded on first use: image_io.h): captured into the one line.
  spectral::StderrCapture open_capture;
  std::string open_error;
  const std::unique_ptr<spectral::PictureReader> in = spectral::open_picture(file, open_error);
  const std::string open_printed = open_capture.finish();
  if (!in) {
    throw InputError(input, "cannot read image " + file + ": " + open_error +
                                spectral::library_said(limits.library, open_printed, open_error));
  }
  CheckedPicture out;
  out.width = in->width();
  out.height = in->height();
  out.channels = in->channels();
  const int w = out.width, h = out.height, nc = out.channels;
  if (w < 1 || h < 1 || nc < 1) throw InputError(input, "image " + file + " is empty");
  if (nc < limits.min_channels) {
    throw InputError(input, "image " + file + " has " + std::to_string(nc) + " channel(s); needs R, G, B");
  }
  const long long pixels = static_cast<long long>(w) * h;
  if (pixels > limits.max_pixels) {
    throw InputError(input, "image " + file + " is " + std::to_string(w) + "×" + std::to_string(h) + " pixels; " +
                                limits.noun + " has at most " + std::to_string(limits.max_pixels) + " pixels");
  }
  const long long decoded = pixels * nc * static_cast<long long>(in->channel_bytes());
  if (ec || decoded > limits.max_expansion * std::max(file_bytes, 1LL)) {
    throw InputError(input, "image " + file + " claims " + std::to_string(w) + "×" + std::to_string(h) + "×" +
                                std::to_string(nc) + " pixels, more than its " + std::to_string(file_bytes) +
                                " bytes can hold (truncated or corrupt)");
  }
  out.pixels.resize(static_cast<std::size_t>(pixels) * nc);
  spectral::StderrCapture read_capture;
  std::string read_error;
  const bool read_ok = in->read_float(out.pixels.data(), read_error);
  const std::string read_printed = read_capture.finish();
  if (!read_ok) {
    throw InputError(input, "cannot read image " + file + ": " + read_error +
                                spectral::library_said(limits.library, read_printed, read_error));
  }
  return out;
}

}  // namespace prizma::render
