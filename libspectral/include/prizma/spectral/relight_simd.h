#pragma once
// The relight row kernel, compiled for every SIMD level and run at the one
// choose_simd_level picks (relight_simd.cpp, Highway; docs/relight.md, "SIMD levels").
#include <cstddef>
#include <string>
#include <vector>

#include "prizma/spectral/simd_choice.h"

namespace prizma::spectral::detail {

// One row of the relight XYZ = Σ_t W_t·V_t: terms with their own value counts, summed in one pass per
// pixel. out[3x + c] = Σ_t Σ_j weights_t[c·n_t + j] · values_t[(first_pixel + x)·n_t + j], x in [0, width).
// A light's transport layer is a term (n_t = bins, weights its 3×n relight matrix); a bispectral
// light's re-radiation weights K (3·|in bins| values per pixel, relight_image.h) are another, with
// weights output[c][c']·ē[in] (relight_image.cpp), so the K·ē product shares the diagonal's row pass.
// `values` must hold the whole row (first_pixel … first_pixel + width − 1).
struct SimdTerm {
  const float* weights;  // 3·n floats, row-major
  const float* values;   // n floats per pixel, pixel-major
  int n;
};
using RelightRowKernel = void (*)(const SimdTerm* terms, int term_count, std::size_t first_pixel, int width, float* out);

// How many running sums per pixel and channel every level keeps (value j goes into sum j mod 16):
// the order of the additions, the same at every level, so every level gives the same bits.
constexpr int kRelightSums = 16;

// The levels the kernel is built for that this CPU runs, lowest first (Baseline always).
std::vector<SimdLevel> relight_simd_levels();
// The level choose_simd_level(SimdKernel::Relight, relight_simd_levels()) picks now.
// Throws InputError("PRIZMA_SIMD", …) for an unknown value of the variable.
SimdLevel relight_simd_level();
// The kernel at relight_simd_level(): look it up once per image, not per row.
RelightRowKernel relight_row_kernel();
// The kernel at `level` (one of relight_simd_levels()).
RelightRowKernel relight_row_kernel(SimdLevel level);
// Highway's name of the target compiled for `level` ("AVX3", "AVX2", "SSE4", "EMU128"…), for labels.
std::string relight_simd_target_name(SimdLevel level);

}  // namespace prizma::spectral::detail
