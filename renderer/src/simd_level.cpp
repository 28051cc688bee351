#include "prizma/render/simd_level.h"

#include <algorithm>
#include <cstdlib>
#include <string>

#include "prizma/spectral/error.h"

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
  const std::vector<SimdLevel> levels = supported_simd_levels();
  SimdLevel best = levels.back();
  if (const char* cap = std::getenv("PRIZMA_SIMD"); cap != nullptr && *cap != '\0')
    best = std::min(best, parse_simd_level(cap, "PRIZMA_SIMD"));
  return best;
}

std::string_view simd_level_name(SimdLevel level) {
  switch (level) {
    case SimdLevel::Avx2:
      return "avx2";
    case SimdLevel::Avx512:
      return "avx512";
    case SimdLevel::Baseline:
      break;
  }
  return "baseline";
}

SimdLevel parse_simd_level(std::string_view name, std::string_view input) {
  for (SimdLevel l : {SimdLevel::Baseline, SimdLevel::Avx2, SimdLevel::Avx512})
    if (name == simd_level_name(l)) return l;
  throw spectral::InputError(std::string(input),
                             "unknown SIMD level \"" + std::string(name) + "\" (known: baseline, avx2, avx512)");
}

}  // namespace prizma::render
