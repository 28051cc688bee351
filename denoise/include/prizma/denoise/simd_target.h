#pragma once
// The SIMD levels the denoiser's inner loops are compiled for (src/kernel_simd.cpp, Highway). Every
// level gives the same bits; tests check it by forcing each one in turn.
#include <string>
#include <vector>

namespace prizma::denoise::detail {

// The targets compiled in that this CPU runs, best first (e.g. "AVX3", "AVX2", "SSE4", …, "EMU128").
std::vector<std::string> simd_targets();
// Tests: use only the named target from now on ("" = back to the best). Not thread-safe.
void force_simd_target(const std::string& name);

}  // namespace prizma::denoise::detail
