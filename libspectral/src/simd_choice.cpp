#include "prizma/spectral/simd_choice.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdlib>
#include <cstring>

#include "prizma/spectral/error.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <cpuid.h>
#endif

namespace prizma::spectral {

namespace {

constexpr SimdLevel kLevels[] = {SimdLevel::Baseline, SimdLevel::Sse4, SimdLevel::Avx2, SimdLevel::Avx512};

// The measured rules. None yet: on the CPUs measured so far (docs/results.md, "SIMD dispatch") every
// kernel's highest level is within 5 % of its fastest, once the relight kernel stopped loading
// unaligned rows 512 bits at a time. A CPU on which bench/simd-table flags a kernel gets a line here,
// e.g. {SimdKernel::Relight, "AuthenticAMD", 0x1A, 0x00, 0xFF, SimdLevel::Avx2, "docs/results.md …"}.
constexpr std::array<SimdRule, 0> kSimdRules{};

// Per kernel: the forced level + 1, or 0 for none.
std::array<std::atomic<int>, std::size(kSimdKernels)> g_forced{};

std::atomic<int>& forced_slot(SimdKernel kernel) { return g_forced[static_cast<std::size_t>(kernel)]; }

std::optional<SimdLevel> forced_level(SimdKernel kernel) {
  const int v = forced_slot(kernel).load();
  return v == 0 ? std::nullopt : std::optional<SimdLevel>(static_cast<SimdLevel>(v - 1));
}

// The highest of `available` at or below `cap`; the lowest available if none is.
SimdLevel highest_at_or_below(std::span<const SimdLevel> available, SimdLevel cap) {
  if (available.empty()) return SimdLevel::Baseline;
  SimdLevel best = available.front();
  for (SimdLevel l : available)
    if (l <= cap) best = std::max(best, l);
  return best;
}

CpuModel read_cpu_model() {
  CpuModel cpu;
#if defined(__x86_64__) && defined(__GNUC__)
  unsigned a = 0, b = 0, c = 0, d = 0;
  if (__get_cpuid(0, &a, &b, &c, &d) == 0) return cpu;
  char vendor[13] = {};
  std::memcpy(vendor, &b, 4);
  std::memcpy(vendor + 4, &d, 4);
  std::memcpy(vendor + 8, &c, 4);
  cpu.vendor = vendor;
  if (__get_cpuid(1, &a, &b, &c, &d) != 0) {
    // The displayed family and model (Intel SDM vol. 2A, CPUID leaf 1; AMD's CPUID specification).
    const int base_family = static_cast<int>((a >> 8) & 0xF), base_model = static_cast<int>((a >> 4) & 0xF);
    cpu.family = base_family == 0xF ? base_family + static_cast<int>((a >> 20) & 0xFF) : base_family;
    cpu.model = (base_family == 0x6 || base_family == 0xF) ? base_model + static_cast<int>(((a >> 16) & 0xF) << 4)
                                                           : base_model;
  }
  unsigned regs[12] = {};
  if (__get_cpuid(0x80000000u, &a, &b, &c, &d) != 0 && a >= 0x80000004u) {
    for (unsigned leaf = 0; leaf < 3; ++leaf)
      __get_cpuid(0x80000002u + leaf, &regs[4 * leaf], &regs[4 * leaf + 1], &regs[4 * leaf + 2], &regs[4 * leaf + 3]);
    char brand[49] = {};
    std::memcpy(brand, regs, 48);
    cpu.brand = brand;
    cpu.brand.erase(0, cpu.brand.find_first_not_of(' '));
  }
#endif
  return cpu;
}

}  // namespace

std::string_view simd_level_name(SimdLevel level) {
  switch (level) {
    case SimdLevel::Sse4:
      return "sse4";
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
  for (SimdLevel l : kLevels)
    if (name == simd_level_name(l)) return l;
  throw InputError(std::string(input),
                   "unknown SIMD level \"" + std::string(name) + "\" (known: baseline, sse4, avx2, avx512)");
}

std::string_view simd_kernel_name(SimdKernel kernel) {
  switch (kernel) {
    case SimdKernel::CompressedFrame:
      return "compressed-frame";
    case SimdKernel::HalfToFloat:
      return "half-to-float";
    case SimdKernel::Tracer:
      return "tracer";
    case SimdKernel::Relight:
      break;
  }
  return "relight";
}

const CpuModel& this_cpu() {
  static const CpuModel cpu = read_cpu_model();
  return cpu;
}

std::span<const SimdRule> simd_rules() { return kSimdRules; }

SimdLevel ruled_simd_level(SimdKernel kernel, std::span<const SimdLevel> available, const CpuModel& cpu,
                           std::span<const SimdRule> rules) {
  SimdLevel cap = SimdLevel::Avx512;
  for (const SimdRule& r : rules)
    if (r.kernel == kernel && r.vendor == cpu.vendor && r.family == cpu.family && cpu.model >= r.model_lo &&
        cpu.model <= r.model_hi)
      cap = std::min(cap, r.highest);
  return highest_at_or_below(available, cap);
}

SimdLevel choose_simd_level(SimdKernel kernel, std::span<const SimdLevel> available, const CpuModel& cpu,
                            std::span<const SimdRule> rules) {
  if (const std::optional<SimdLevel> forced = forced_level(kernel)) return highest_at_or_below(available, *forced);
  if (const char* env = std::getenv("PRIZMA_SIMD"); env != nullptr && *env != '\0')
    return highest_at_or_below(available, parse_simd_level(env, "PRIZMA_SIMD"));
  return ruled_simd_level(kernel, available, cpu, rules);
}

void force_simd_level(SimdKernel kernel, std::optional<SimdLevel> level) {
  forced_slot(kernel).store(level ? static_cast<int>(*level) + 1 : 0);
}

ForcedSimdLevel::ForcedSimdLevel(SimdKernel kernel, std::optional<SimdLevel> level)
    : m_kernel(kernel), m_previous(forced_level(kernel)) {
  force_simd_level(kernel, level);
}

ForcedSimdLevel::~ForcedSimdLevel() { force_simd_level(m_kernel, m_previous); }

}  // namespace prizma::spectral
