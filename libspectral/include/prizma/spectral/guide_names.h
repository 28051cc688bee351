#pragma once
// Which guide layers (SpectralImage::guides) are exact rather than Monte Carlo means.
#include <string>

namespace prizma::spectral {

// True for the guide layers the renderer computes deterministically, not by Monte Carlo: the first
// hit of the camera rays ("hit_…": docs/spectral-exr.md, "Guide layers"). Their values are the same
// whatever the samples, seed or shard, and their variance is the spread over the pixel's fixed
// sub-pixel rays (so merge keeps them as they are and the denoiser does not prefilter them).
inline bool exact_guide(const std::string& name) { return name.rfind("hit_", 0) == 0; }

}  // namespace prizma::spectral
