#pragma once
// The relight row kernel with run-time SIMD dispatch (relight_simd.cpp, Highway).
#include <cstddef>
#include <string>
#include <vector>

namespace prizma::relight::detail {

// One row of the relight XYZ = Σ_t W_t·V_t: terms with their own value counts, summed in one pass per
// pixel. out[3x + c] = Σ_t Σ_j weights_t[c·n_t + j] · values_t[(first_pixel + x)·n_t + j], x in [0, width).
// A light's transport layer is a term (n_t = bins, weights its 3×n relight matrix); a bispectral
// light's re-radiation weights K (3·|in bins| values per pixel, relight_image.h) are another, with
// weights output[c][c']·ē[in] (relight_image.cpp), so the K·ē product shares the diagonal's row pass.
struct SimdTerm {
  const float* weights;  // 3·n floats, row-major
  const float* values;   // n floats per pixel, pixel-major
  int n;
};
void relight_row_terms_simd(const SimdTerm* terms, int term_count, std::size_t first_pixel, int width, float* out);

// The targets compiled in that this CPU runs, best first (e.g. "AVX3", "AVX2", "SSE4", …, "EMU128").
std::vector<std::string> relight_simd_targets();
// The one relight_row_terms_simd uses now.
std::string relight_simd_target();
// Tests: use only the named target from now on ("" = back to the best). Not thread-safe.
void relight_simd_force_target(const std::string& name);

}  // namespace prizma::relight::detail
