#pragma once
// The denoiser's inner loops (kernel_simd.cpp), compiled for every x86 SIMD level with Highway and
// chosen at run time. They use only IEEE-exact per-lane operations (add, multiply, divide, min,
// max, rounding, bit operations; never a fused multiply-add), so every level, and every position of
// a pixel in its tile, gives the same bits.
#include <cstddef>

namespace prizma::denoise::detail {

// Rows are padded to a multiple of this many floats (the widest vector, AVX-512), so the loops
// only ever run over whole vectors.
inline constexpr int kPadFloats = 16;
inline int padded(int n) { return (n + kPadFloats - 1) / kPadFloats * kPadFloats; }

// One feature plane of a tile: value and variance on the tile grown by r on every side (clamped
// to the image), `stride` floats per row; `denominator` per tile pixel (row stride tile_wp).
struct TileFeature {
  const float* value;
  const float* variance;
  const float* denominator;  // k_f²·max(τ, V_p, |∇f_p|²)
};

// One neighbour offset (dx, dy) of a tile: its unnormalised weights w = exp(−max(e_colour,
// e_feature)) for every tile pixel, e_colour = max(0, D²/k²) + max(0, z² − t²), D² the patch mean of
// d² = ((a − b)² − (V_a + min(V_a, V_b))) / (ε + V_a + V_b), e_feature = max over features of
// max(0, d_f²) (docs/denoise.md). The patch distance is computed once for up to kMaxCandidates
// values of 1/k² per pixel (the candidates the SURE selection compares, or the chosen one), each
// with its own output. Exponents above kCutExponent give 0.
inline constexpr int kMaxCandidates = 2;
struct OffsetJob {
  // Tile size and padded width (a multiple of kPadFloats).
  int tile_w = 0, tile_h = 0, tile_wp = 0;
  int window_radius = 0, patch_radius = 0;
  int dx = 0, dy = 0;
  // Luminance and its variance on the tile grown by r + f (clamped), `lum_stride` floats per row.
  const float* lum = nullptr;
  const float* lum_var = nullptr;
  int lum_stride = 0;
  float eps = 0.0f;          // ε of the distances
  float centre_t2 = 0.0f;    // t² of the centre test (standard errors squared), 0 = none
  float inv_patch_area = 0.0f;
  // Per candidate: 1/k² per tile pixel (tile_h rows of tile_wp) and the output, tile_h rows of
  // tile_wp weights.
  int candidates = 1;
  const float* inv_k2[kMaxCandidates] = {};
  float* weights[kMaxCandidates] = {};
  const TileFeature* features = nullptr;
  int feature_count = 0;
  int feature_stride = 0;
  // Scratch of at least (tile_h + 2f)·region_wp floats each, region_wp = padded(tile_wp + 2f).
  float* d2 = nullptr;
  float* hsum = nullptr;
};
inline constexpr float kCutExponent = 20.0f;  // e^-20 = 2e-9 of the centre pixel's weight

void offset_weights(const OffsetJob& job);

// Divides each of `count` pixels' weights by their sum over the `kernel_size` offsets (offset-major,
// plane stride `count`, a multiple of kPadFloats), summed in offset order.
void normalise_kernels(float* kernels, int kernel_size, int count);

// acc[y·acc_stride + x] += w[y·w_stride + x] · v[y·v_stride + x] for y < rows, x < width (a
// multiple of kPadFloats), multiply then add.
void multiply_add_rows(const float* w, int w_stride, const float* v, int v_stride, float* acc, int acc_stride, int rows,
                       int width);

// A plane the kernels are applied to: `channels` floats per pixel, pixel-major, whole image.
struct ApplyPlane {
  const float* in = nullptr;
  float* out = nullptr;
  int channels = 0;
  bool squared = false;  // Σ W²·in (variance) instead of Σ W·in
};

// out(p) = Σ_taps w·in(p + delta) for one pixel p and every plane: `taps` neighbours with their pixel
// index offset and weight (zero weights left out by the caller), in offset order.
void apply_pixel(const ApplyPlane* planes, int plane_count, std::ptrdiff_t pixel, const std::ptrdiff_t* delta,
                 const float* weight, const float* weight_squared, int taps);

}  // namespace prizma::denoise::detail
