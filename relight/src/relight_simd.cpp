// The relight inner loop XYZ = Σ_l M_l·T_l for a row of pixels, compiled for every x86 SIMD level
// (SSSE3, SSE4, AVX2, AVX-512, and a portable fallback) with Highway; the best one the CPU has is
// chosen at run time (HWY_DYNAMIC_DISPATCH). The builds use the default x86-64 flags (SSE2), so
// without this the loop never used AVX2's FMA or AVX-512 (docs/results.md, "Relight throughput").
// The targets sum in different orders (their lane counts differ): results agree within float
// rounding (tests/relight/relight_simd_test.cpp), and one machine always gives the same bits.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "relight_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep
#include <hwy/highway.h>

#include "prizma/relight/relight_simd.h"

HWY_BEFORE_NAMESPACE();
namespace prizma::relight::detail::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// out[3x + c] = Σ_t Σ_j w_t[c·n_t + j]·v_t[(first_pixel + x)·n_t + j] (relight_simd.h, SimdTerm): per
// pixel, three vector accumulators over every term's full vectors, a scalar sum over each tail.
void RelightRowTermsSimd(const SimdTerm* terms, int term_count, std::size_t first_pixel, int width, float* out) {
  const hn::ScalableTag<float> d;
  const std::size_t lanes = hn::Lanes(d);
  for (int x = 0; x < width; ++x) {
    const std::size_t p = first_pixel + static_cast<std::size_t>(x);
    auto a0 = hn::Zero(d);
    auto a1 = hn::Zero(d);
    auto a2 = hn::Zero(d);
    float t0 = 0.0f, t1 = 0.0f, t2 = 0.0f;
    for (int l = 0; l < term_count; ++l) {
      const std::size_t nb = static_cast<std::size_t>(terms[l].n);
      const std::size_t full = nb - nb % lanes;
      const float* HWY_RESTRICT w = terms[l].weights;
      const float* HWY_RESTRICT t = terms[l].values + p * nb;
      std::size_t i = 0;
      for (; i < full; i += lanes) {
        const auto v = hn::LoadU(d, t + i);
        a0 = hn::MulAdd(hn::LoadU(d, w + i), v, a0);
        a1 = hn::MulAdd(hn::LoadU(d, w + nb + i), v, a1);
        a2 = hn::MulAdd(hn::LoadU(d, w + 2 * nb + i), v, a2);
      }
      for (; i < nb; ++i) {
        t0 += w[i] * t[i];
        t1 += w[nb + i] * t[i];
        t2 += w[2 * nb + i] * t[i];
      }
    }
    out[3 * x + 0] = hn::GetLane(hn::SumOfLanes(d, a0)) + t0;
    out[3 * x + 1] = hn::GetLane(hn::SumOfLanes(d, a1)) + t1;
    out[3 * x + 2] = hn::GetLane(hn::SumOfLanes(d, a2)) + t2;
  }
}

}  // namespace prizma::relight::detail::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace prizma::relight::detail {

HWY_EXPORT(RelightRowTermsSimd);

void relight_row_terms_simd(const SimdTerm* terms, int term_count, std::size_t first_pixel, int width, float* out) {
  HWY_DYNAMIC_DISPATCH(RelightRowTermsSimd)(terms, term_count, first_pixel, width, out);
}

std::vector<std::string> relight_simd_targets() {
  std::vector<std::string> names;
  for (const std::int64_t t : hwy::SupportedAndGeneratedTargets()) names.emplace_back(hwy::TargetName(t));
  return names;
}

std::string relight_simd_target() {
  const std::vector<std::int64_t> targets = hwy::SupportedAndGeneratedTargets();  // best first
  return targets.empty() ? std::string("none") : std::string(hwy::TargetName(targets.front()));
}

void relight_simd_force_target(const std::string& name) {
  if (name.empty()) {
    hwy::SetSupportedTargetsForTest(0);
    return;
  }
  for (const std::int64_t t : hwy::SupportedAndGeneratedTargets()) {
    if (name == hwy::TargetName(t)) {
      hwy::SetSupportedTargetsForTest(t);
      return;
    }
  }
}

}  // namespace prizma::relight::detail
#endif
