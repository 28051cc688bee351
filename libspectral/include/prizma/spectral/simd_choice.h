#pragma once
// Which instruction-set level each run-time dispatched kernel runs at (docs/relight.md and
// docs/renderer.md, "SIMD levels"; the measurements: docs/results.md, "SIMD dispatch"). Every
// kernel gives the same bits at every level, so the choice changes speed only:
//   1. a level forced in this process (force_simd_level: tests, benchmarks), else
//   2. the environment variable PRIZMA_SIMD (baseline | sse4 | avx2 | avx512), else
//   3. the highest level the kernel has on this CPU, unless a measured rule (kSimdRules in
//      simd_choice.cpp) caps it for this CPU.
// A level the kernel or the CPU lacks falls to the highest available one below it.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace prizma::spectral {

// x86-64 levels, lowest first: Baseline = the build's own flags (SSE2) or Highway's portable
// fallback; Sse4 = SSE4.1/4.2; Avx2 = AVX2 + FMA; Avx512 = AVX-512 F/VL/BW/DQ.
enum class SimdLevel { Baseline, Sse4, Avx2, Avx512 };

// "baseline", "sse4", "avx2", "avx512".
std::string_view simd_level_name(SimdLevel level);
// The inverse of simd_level_name; InputError(input, "unknown SIMD level …") for another name.
SimdLevel parse_simd_level(std::string_view name, std::string_view input);

// The kernels dispatched at run time, each chosen on its own.
enum class SimdKernel {
  Relight,          // Σ_l M_l·T_l per pixel, bispectral terms included (relight_simd.cpp)
  CompressedFrame,  // half coefficients → display RGB → 8-bit codes (compressed_simd.cpp)
  HalfToFloat,      // half → float rows of relight_compressed_into (compressed_simd.cpp)
  Tracer,           // PathTracer::trace (path_tracer.cpp)
};
inline constexpr SimdKernel kSimdKernels[] = {SimdKernel::Relight, SimdKernel::CompressedFrame, SimdKernel::HalfToFloat,
                                              SimdKernel::Tracer};
// "relight", "compressed-frame", "half-to-float", "tracer".
std::string_view simd_kernel_name(SimdKernel kernel);

// The CPU as the rules key it: CPUID vendor ("AuthenticAMD", "GenuineIntel"), family and model
// (extended fields folded in, as /proc/cpuinfo prints them), brand string. Empty/0 off x86.
struct CpuModel {
  std::string vendor;
  int family = 0;
  int model = 0;
  std::string brand;
};
const CpuModel& this_cpu();

// A measured rule: on CPUs of `vendor` and `family` with model in [model_lo, model_hi], `kernel`
// runs at most at `highest`. Each rule names the measurement that backs it.
struct SimdRule {
  SimdKernel kernel;
  std::string_view vendor;
  int family;
  int model_lo, model_hi;
  SimdLevel highest;
  std::string_view measured;  // where: "docs/results.md, SIMD dispatch, <date>"
};
// Prizma's rules (simd_choice.cpp).
std::span<const SimdRule> simd_rules();

// The level `kernel` runs at, given `available` (the levels it is built for that this CPU runs,
// lowest first, never empty) and `rules`, in the order of the header comment. Throws
// InputError("PRIZMA_SIMD", …) for an unknown value of the variable.
SimdLevel choose_simd_level(SimdKernel kernel, std::span<const SimdLevel> available, const CpuModel& cpu = this_cpu(),
                            std::span<const SimdRule> rules = simd_rules());
// The level the rules alone give (no forcing, no PRIZMA_SIMD): what the tools run without either.
SimdLevel ruled_simd_level(SimdKernel kernel, std::span<const SimdLevel> available, const CpuModel& cpu = this_cpu(),
                           std::span<const SimdRule> rules = simd_rules());

// Tests and benchmarks: run `kernel` at `level` (or the highest available below it) from the next
// choice on, in this process; std::nullopt goes back to PRIZMA_SIMD and the rules. Thread-safe, but
// a kernel already running keeps the level it chose.
void force_simd_level(SimdKernel kernel, std::optional<SimdLevel> level);

// Sets a forced level for its lifetime and puts the previous one back.
class ForcedSimdLevel {
 public:
  ForcedSimdLevel(SimdKernel kernel, std::optional<SimdLevel> level);
  ~ForcedSimdLevel();
  ForcedSimdLevel(const ForcedSimdLevel&) = delete;
  ForcedSimdLevel& operator=(const ForcedSimdLevel&) = delete;

 private:
  SimdKernel m_kernel;
  std::optional<SimdLevel> m_previous;
};

}  // namespace prizma::spectral
