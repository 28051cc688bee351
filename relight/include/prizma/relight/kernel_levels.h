#pragma once
// The SIMD levels of each relight kernel (spectral::SimdKernel::Relight, whose kernel is
// libspectral's relight_simd.h, CompressedFrame and HalfToFloat, this library's compressed_simd.cpp;
// the Tracer's are render::supported_simd_levels()), for tests and benchmarks: the levels built that
// this CPU runs, lowest first, and the one the tools run the kernel at now.
#include <vector>

#include "prizma/spectral/simd_choice.h"

namespace prizma::relight::detail {

// Throws RuntimeError for SimdKernel::Tracer (not a relight kernel).
std::vector<spectral::SimdLevel> kernel_simd_levels(spectral::SimdKernel kernel);
spectral::SimdLevel kernel_simd_level(spectral::SimdKernel kernel);

}  // namespace prizma::relight::detail
