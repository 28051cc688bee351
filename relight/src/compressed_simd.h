#pragma once
// The fused row kernel of relight_compressed_to_display8 (compressed_simd.cpp, Highway run-time
// dispatch like relight_simd.cpp): coefficients → linear display RGB → 8-bit codes, one row at a time.
#include <cstddef>
#include <cstdint>

namespace prizma::relight::detail {

// One light: its 3×k weights, row-major (R, G, B rows: the display matrix folded in), and its
// coefficients (pixel-major, k contiguous).
struct SimdCoeffLayer {
  const float* weights;
  const float* coefficients;
  int k;
};

// DisplayEncoder8's small table per channel: code(v) = lut[min(v·scale, size−1)] (+1 when v ≥
// thresholds[code + 1]), v clamped below at 0; thresholds[256] = +∞.
struct SimdEncoder {
  const std::int32_t* lut[3] = {nullptr, nullptr, nullptr};
  const float* thresholds[3] = {nullptr, nullptr, nullptr};
  int lut_size = 0;
  float lut_scale = 0.0f;
};

// out[3x + c] for x in [0, width): the codes of pixel first_pixel + x. `scratch`: 3·width + 64 floats.
void compressed_row_to_display8(const SimdCoeffLayer* layers, int layer_count, std::size_t first_pixel, int width,
                                const SimdEncoder& encoder, float* scratch, std::uint8_t* out);

}  // namespace prizma::relight::detail
