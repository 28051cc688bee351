#pragma once
// The fused row kernel of relight_compressed_to_display8 (compressed_simd.cpp, compiled for every
// SIMD level and run at the one spectral::choose_simd_level picks, like relight_simd.cpp): half
// coefficients → linear display RGB → 8-bit codes, one row at a time; and the half → float
// conversion of relight_compressed_into. Every level gives the same bytes.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "prizma/spectral/simd_choice.h"

namespace prizma::relight::detail {

// One light: its 3×k weights, row-major (R, G, B rows: the display matrix folded in), and its
// coefficients as IEEE binary16 bits (pixel-major, k contiguous).
struct SimdCoeffLayer {
  const float* weights;
  const std::uint16_t* coefficients;
  int k;
};

// DisplayEncoder8's step table (DisplayEncoder8::StepTable): for the bits b of linear v (v < 0 and NaN
// as 0) clamped to [lo_bits, hi_bits], e = entries[c][(b >> shift) − base] and
// code = (e & 255) + ((b & (2^shift − 1)) ≥ (e >> 8)).
struct SimdEncoder {
  const std::uint32_t* entries[3] = {nullptr, nullptr, nullptr};
  int shift = 0;
  std::int32_t base = 0, lo_bits = 0, hi_bits = 0;
};

// The most float lanes of any target (AVX-512: 16), and the most lights one fused row takes.
constexpr int kMaxSimdLanes = 16;
constexpr int kMaxFusedLayers = 64;

// Floats of scratch compressed_row_to_display8 needs for a row of `width` pixels: per layer with
// k > 4 its row of coefficients as floats, plus a block of zero padding.
inline std::size_t compressed_row_scratch(const SimdCoeffLayer* layers, int layer_count, int width) {
  std::size_t n = 0;
  for (int l = 0; l < layer_count; ++l)
    if (layers[l].k > 4) n += static_cast<std::size_t>(width + kMaxSimdLanes) * static_cast<std::size_t>(layers[l].k);
  return n;
}

// out[3x + c] for x in [0, width): the codes of pixel first_pixel + x. At most kMaxFusedLayers
// layers; `scratch`: compressed_row_scratch(layers, layer_count, width) floats.
using CompressedRowKernel = void (*)(const SimdCoeffLayer* layers, int layer_count, std::size_t first_pixel, int width,
                                     const SimdEncoder& encoder, float* scratch, std::uint8_t* out);
// The levels it is built for that this CPU runs (lowest first), and the kernel at the level chosen
// for SimdKernel::CompressedFrame now (look it up once per frame) or at a given one.
std::vector<spectral::SimdLevel> compressed_frame_levels();
CompressedRowKernel compressed_row_kernel();
CompressedRowKernel compressed_row_kernel(spectral::SimdLevel level);

// out[i] = the float of half bits in[i] (exact), i < count. The same for SimdKernel::HalfToFloat.
using HalfToFloatKernel = void (*)(const std::uint16_t* in, std::size_t count, float* out);
std::vector<spectral::SimdLevel> half_to_float_levels();
HalfToFloatKernel half_to_float_kernel();
HalfToFloatKernel half_to_float_kernel(spectral::SimdLevel level);
// One conversion through half_to_float_kernel() (outside loops over rows or pixels).
inline void half_to_float(const std::uint16_t* in, std::size_t count, float* out) { half_to_float_kernel()(in, count, out); }

}  // namespace prizma::relight::detail
