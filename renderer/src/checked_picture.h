#pragma once
// read_picture_checked: an image the scene names (an environment map, a transfer-function image)
// read through the image module with the checks both need before anything large is allocated.
#include <filesystem>
#include <string>
#include <vector>

namespace prizma::render {

// What is read, for the messages and the limits.
struct PictureLimits {
  const char* kind;             // "an environment image": the regular-file check's words
  const char* noun;             // "an environment map": "… has at most N pixels"
  const char* library;          // who printed on stderr, for the one error line ("libpng", "image library")
  long long max_pixels;         // width × height at most
  long long max_expansion;      // decoded bytes per byte of file at most (a truncated or lying header)
  int min_channels = 1;         // fewer: "has N channel(s); needs R, G, B"
};

struct CheckedPicture {
  int width = 0, height = 0, channels = 0;
  std::vector<float> pixels;  // width · height · channels floats, interleaved, rows top first
};

// Reads `path` whole as floats. Throws InputError(input, …) naming the file: not a regular file,
// cannot be read (with what the library printed), empty, too few channels, more pixels than
// limits.max_pixels, more decoded bytes than its size can hold.
CheckedPicture read_picture_checked(const std::filesystem::path& path, const PictureLimits& limits,
                                    const std::string& input);

}  // namespace prizma::render
