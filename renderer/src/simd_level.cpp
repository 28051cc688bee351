#include "prizma/render/simd_level.h"

namespace prizma::render {

std::vector<SimdLevel> supported_simd_levels() {
  std::vector<SimdLevel> levels{SimdLevel::Baseline};
#if defined(__x86_64__) && defined(__GNUC__)
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
    levels.push_back(SimdLevel::Avx2);
    if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
        __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq"))
      levels.push_back(SimdLevel::Avx512);
  }
#endif
  return levels;
}

SimdLevel default_simd_level() {
  return spectral::choose_simd_level(spectral::SimdKernel::Tracer, supported_simd_levels());
}

}  // namespace prizma::render
