#pragma once
// SimdLevel: the x86 instruction sets the path tracer is compiled for, one of which it runs on,
// chosen at run time from what the CPU has (docs/renderer.md, "SIMD levels"). The builds target
// baseline x86-64 (SSE2); the tracer is also compiled for AVX2 and AVX-512 and every level gives
// the same bits (IEEE operations in the same order, no FMA contraction, no reassociated sums).
#include <string_view>
#include <vector>

namespace prizma::render {

enum class SimdLevel { Baseline, Avx2, Avx512 };

// Levels this CPU can run, lowest first (Baseline always; Avx2 needs AVX2 + FMA, Avx512 also
// AVX-512 F/VL/BW/DQ; only Baseline on a non-x86 build).
std::vector<SimdLevel> supported_simd_levels();
// The level a PathTracer uses unless told otherwise: the highest supported one, capped by the
// environment variable PRIZMA_SIMD (baseline | avx2 | avx512) for checks and benchmarks; an unknown
// value throws InputError("PRIZMA_SIMD", …).
SimdLevel default_simd_level();
// "baseline", "avx2", "avx512".
std::string_view simd_level_name(SimdLevel level);
// The inverse of simd_level_name; InputError(input, …) for another name.
SimdLevel parse_simd_level(std::string_view name, std::string_view input);

}  // namespace prizma::render
