#pragma once
// Highway kernels chosen per kernel (choose_simd_level) instead of through
// HWY_DYNAMIC_DISPATCH, whose one target is global to the process (libhwy.so's, shared with any
// other library using Highway) and always the widest the CPU has. Include in the HWY_ONCE part of a
// file that compiles its kernels with foreach_target.h; `table` is HWY_DISPATCH_TABLE(Function)
// after HWY_EXPORT(Function).
#include <hwy/highway.h>

#include <cstdint>
#include <string>
#include <vector>

#include "prizma/spectral/simd_choice.h"

namespace prizma::spectral::detail {

#if HWY_ARCH_X86 && (HWY_TARGETS & (HWY_TARGETS - 1)) != 0
// The Highway target compiled for a level; Baseline is the table's portable fallback.
inline std::int64_t hwy_target_of(SimdLevel level) {
  switch (level) {
    case SimdLevel::Sse4:
      return HWY_SSE4;
    case SimdLevel::Avx2:
      return HWY_AVX2;
    case SimdLevel::Avx512:
      return HWY_AVX3;
    case SimdLevel::Baseline:
      break;
  }
  return (HWY_TARGETS & HWY_EMU128) != 0 ? HWY_EMU128 : HWY_SCALAR;
}

// Levels whose target is compiled into `table` and runs on this CPU, lowest first.
template <class Fn>
std::vector<SimdLevel> hwy_levels(const Fn* table) {
  std::vector<SimdLevel> levels{SimdLevel::Baseline};
  for (SimdLevel l : {SimdLevel::Sse4, SimdLevel::Avx2, SimdLevel::Avx512}) {
    const std::int64_t target = hwy_target_of(l);
    if ((target & HWY_TARGETS & hwy::SupportedTargets()) == 0) continue;
    // The table's slot for a target (highway.h, HWY_EXPORT; targets.h, ChosenTarget::GetIndex).
    const std::size_t slot = hwy::Num0BitsBelowLS1Bit_Nonzero64(static_cast<std::uint64_t>(HWY_CHOSEN_TARGET_SHIFT(target)));
    if (table[slot] != nullptr) levels.push_back(l);
  }
  return levels;
}

// The function compiled for `level` (one of hwy_levels(table)).
template <class Fn>
Fn hwy_function(const Fn* table, SimdLevel level) {
  if (level == SimdLevel::Baseline) return table[HWY_MAX_DYNAMIC_TARGETS + 1];
  return table[hwy::Num0BitsBelowLS1Bit_Nonzero64(static_cast<std::uint64_t>(HWY_CHOSEN_TARGET_SHIFT(hwy_target_of(level))))];
}
#else
// One target compiled (a build for one instruction set), or not x86: one level, "baseline", which
// is the table's first slot: the static target, or Highway's own run-time choice.
inline std::int64_t hwy_target_of(SimdLevel) { return HWY_STATIC_TARGET; }
template <class Fn>
std::vector<SimdLevel> hwy_levels(const Fn*) {
  return {SimdLevel::Baseline};
}
template <class Fn>
Fn hwy_function(const Fn* table, SimdLevel) {
  return table[0];
}
#endif

// "AVX3", "AVX2", "SSE4", "EMU128", …: Highway's name of the target behind a level.
inline std::string hwy_target_name(SimdLevel level) { return hwy::TargetName(hwy_target_of(level)); }

// A row kernel compiled for every level (`table`: HWY_DISPATCH_TABLE(Function)) and the SimdKernel
// whose rule picks its level: the one dispatch of every Highway kernel here (the relight rows
// here, the compressed relight rows and the half → float conversion in relight/).
template <class Fn>
struct HwyKernel {
  const Fn* table;
  SimdKernel kind;

  // The levels it is built for that this CPU runs, lowest first (Baseline always).
  std::vector<SimdLevel> levels() const { return hwy_levels(table); }
  // The level choose_simd_level(kind, levels()) picks now (throws InputError("PRIZMA_SIMD", …)
  // for an unknown value of the variable).
  SimdLevel chosen_level() const { return choose_simd_level(kind, levels()); }
  // The kernel at `level` (one of levels()), or at chosen_level(): look it up once per image.
  Fn at(SimdLevel level) const { return hwy_function(table, level); }
  Fn chosen() const { return at(chosen_level()); }
};

}  // namespace prizma::spectral::detail
