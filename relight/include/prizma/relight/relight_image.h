#pragma once
// relight_image: the per-pixel evaluation XYZ = Σ_l M_l · T_l over a whole spectral image.
#include "prizma/relight/relight_matrix.h"
#include "prizma/relight/xyz_image.h"
#include "prizma/spectral/spectral_exr.h"

namespace prizma::relight {

// Pure function: relights every pixel (TBB, parallel over rows, one pass over the transport, no
// per-pixel allocation). The result does not depend on the thread count. Throws RuntimeError when
// the matrix does not match the image's layer or bin count.
XyzImage relight_image(const spectral::SpectralImage& image, const RelightMatrix& matrix);

// The same into a caller-owned buffer of 3·width·height floats (reused across interactive relights).
void relight_into(const spectral::SpectralImage& image, const RelightMatrix& matrix, float* xyz_out);

}  // namespace prizma::relight
