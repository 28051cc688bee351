#pragma once
// relight_image: the per-pixel evaluation XYZ = Σ_l M_l · T_l over a whole spectral image.
#include <string>
#include <vector>

#include "prizma/spectral/relight_matrix.h"
#include "prizma/spectral/xyz_image.h"
#include "prizma/spectral/spectral_exr.h"

namespace prizma::spectral {

// Pure function: relights every pixel (TBB, parallel over rows, one pass over the transport, no
// per-pixel allocation). The result does not depend on the thread count. Throws RuntimeError when
// the matrix does not match the image's layer or bin count.
XyzImage relight_image(const SpectralImage& image, const RelightMatrix& matrix);

// The per-pixel weights K[c][in] = Σ_out cmf_c(out)·M[out][in] of every light of a bispectral
// (fluorescent) image, for one observer (reradiation_colour_weights); empty per_light for
// a diagonal image. Computed once per image and observer: relighting then adds K·ē per pixel.
struct ReradiationWeights {
  Observer cmf = Observer::Cie1931_2deg;
  std::vector<int> in_bins;
  std::vector<std::vector<float>> per_light;  // [light]: pixels × 3 × in_bins.size()
};
ReradiationWeights reradiation_weights(const SpectralImage& image, Observer cmf);

// The weights that relight_into gives light `light`'s K in its row pass (and the live page its K
// textures): 3 rows (X, Y, Z) × values_per_pixel = 3·|in bins|, W[c][c'·|in| + j] =
// output()[c][c']·ē[in_bins[j]], so W·K = output · K·ē. Double; relight_into rounds them to float.
struct ReradiationTermWeights {
  int values_per_pixel = 0;
  std::vector<double> weights;  // row-major, 3 × values_per_pixel
};
ReradiationTermWeights reradiation_term_weights(const RelightMatrix& matrix, const ReradiationWeights& k, int light);

// The set-up every relight kernel shares (relight_into, relight_compressed_into): checks that `matrix`
// has `layers` lights of `bins` bins (RuntimeError naming `what`, e.g. "image", otherwise) and returns
// the lights that are on, each with its 3×n weights as float, row-major (X, Y, Z rows). Lights whose
// matrix is zero ("off") are left out, so the kernels skip them entirely.
struct LightWeights {
  int light = 0;
  std::vector<float> weights;
};
std::vector<LightWeights> light_weights(const RelightMatrix& matrix, int layers, int bins, const std::string& what);

// The same into a caller-owned buffer of 3·width·height floats (reused across interactive relights).
// For a bispectral image, `k` (for the matrix's observer) is used when given, else computed.
void relight_into(const SpectralImage& image, const RelightMatrix& matrix, float* xyz_out,
                  const ReradiationWeights* k = nullptr);

}  // namespace prizma::spectral
