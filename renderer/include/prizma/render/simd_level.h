#pragma once
// The tracer's SIMD levels: PathTracer::trace is compiled for the baseline x86-64 flags (SSE2), for
// AVX2 and for AVX-512, and runs at the level spectral::choose_simd_level picks for
// SimdKernel::Tracer (docs/renderer.md, "SIMD levels"): PRIZMA_SIMD when set, else the highest
// this CPU has unless a measured rule says otherwise. Every level gives the same bits (IEEE
// operations in the same order, no FMA contraction, no reassociated sums).
#include <string_view>
#include <vector>

#include "prizma/spectral/simd_choice.h"

namespace prizma::render {

using spectral::parse_simd_level;
using spectral::simd_level_name;
using spectral::SimdLevel;

// Levels the tracer has that this CPU runs, lowest first: Baseline always; Avx2 needs AVX2 + FMA,
// Avx512 also AVX-512 F/VL/BW/DQ; only Baseline on a non-x86 build. (The tracer has no Sse4 level.)
std::vector<SimdLevel> supported_simd_levels();
// The level a PathTracer uses unless told otherwise: spectral::choose_simd_level(SimdKernel::Tracer,
// supported_simd_levels()). An unknown PRIZMA_SIMD throws InputError("PRIZMA_SIMD", …).
SimdLevel default_simd_level();

}  // namespace prizma::render
