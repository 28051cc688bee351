#pragma once
// Float values as a half-float file holds them: IEEE binary16 with OpenEXR's conversion (round to
// nearest, ties to even; beyond ±65504 ±inf), read back as float. What a reader of a file written
// with ExrPixelType::Half gets, for what is computed from a file before it is read back (the
// render's --preview of a --half render).
#include <vector>

namespace prizma::spectral {

void round_to_half(std::vector<float>& values);

}  // namespace prizma::spectral
