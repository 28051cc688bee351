#pragma once
// What a Prizma file lacks that its checksum covers, when the pixels do not match prizma:checksum:
// channels another tool left out (oiiotool --ch keeps prizma:checksum and drops what it is not
// given), named so that the error says what is missing rather than "probably re-encoded".
#include <string>

#include "prizma/spectral/spectral_exr.h"

namespace prizma::spectral::detail {

// The parts a Prizma writer puts in every such file and the file read into `image` has not: the
// top-level T layer of a file of two or more lights (when the checksum covers it: `covers_top`, v2),
// the variance layers of some lights but not others, or of every light when prizma:renderOptions
// records "variance": true. "" when nothing is missing. `has_top`: the file has the top-level layer.
std::string missing_channels(const SpectralImage& image, bool has_top, bool covers_top);

}  // namespace prizma::spectral::detail
