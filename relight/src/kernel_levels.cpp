#include "prizma/relight/kernel_levels.h"

#include "compressed_simd.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/relight_simd.h"

namespace prizma::relight::detail {

std::vector<spectral::SimdLevel> kernel_simd_levels(spectral::SimdKernel kernel) {
  switch (kernel) {
    case spectral::SimdKernel::CompressedFrame:
      return compressed_frame_levels();
    case spectral::SimdKernel::HalfToFloat:
      return half_to_float_levels();
    case spectral::SimdKernel::Tracer:
      throw spectral::RuntimeError("kernel_simd_levels: the tracer's levels are render::supported_simd_levels()");
    case spectral::SimdKernel::Relight:
      break;
  }
  return spectral::detail::relight_simd_levels();
}

spectral::SimdLevel kernel_simd_level(spectral::SimdKernel kernel) {
  return spectral::choose_simd_level(kernel, kernel_simd_levels(kernel));
}

}  // namespace prizma::relight::detail
