#pragma once
// The OpenEXR 3.1 header guard (internal): a header whose declared sizes disagree with its bytes is
// refused before OpenEXR reads it (header_guard.cpp says why).
#include <string>

namespace prizma::spectral::exr {

// Walks the header(s) of the file at `path` and throws InputError(path, …) for an attribute whose
// declared size is larger than the bytes left or disagrees with its content.
void check_header_sizes(const std::string& path);

}  // namespace prizma::spectral::exr
