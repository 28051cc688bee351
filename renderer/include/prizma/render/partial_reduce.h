#pragma once
// Reductions over the lanes of a path in partial results: lane i goes into partial i mod kWidth,
// in lane order, and the partials are combined in order at the end. The order is fixed, so every
// SIMD level of the tracer gives the same bits (path_tracer.cpp is built without -ffast-math and
// without FMA contraction: tests/render/test_simd_levels.cpp), and GCC vectorises the loops, which
// it does not for a single running float sum or max. x is anything with x[i] → float.
#include <algorithm>

namespace prizma::render::partial {

constexpr int kWidth = 8;

// max(+0, the largest x[i]): the same bits as the sequential loop m = std::max(m, x[i]) from
// m = 0, whatever the order, since every partial starts at +0 and std::max(m, x) never takes a
// NaN, nor −0 over +0, and equal values other than zeros have equal bits.
template <class X>
float max_from_zero(const X& x, int n) {
  float part[kWidth] = {};
  int i = 0;
  for (; i + kWidth <= n; i += kWidth)
    for (int k = 0; k < kWidth; ++k) part[k] = std::max(part[k], x[i + k]);
  for (int k = 0; i < n; ++i, ++k) part[k] = std::max(part[k], x[i]);
  float m = 0.0f;
  for (int k = 0; k < kWidth; ++k) m = std::max(m, part[k]);
  return m;
}

// min(+∞, the least x[i]): for n ≥ 1 and no NaN, the value of the sequential loop m = std::min(m,
// x[i]) from m = x[0], whatever the order (its bits too, but for which of +0 and −0 a tie of zeros
// keeps; they compare equal).
template <class X>
float min_from_infinity(const X& x, int n) {
  constexpr float kInf = __builtin_huge_valf();
  float part[kWidth] = {kInf, kInf, kInf, kInf, kInf, kInf, kInf, kInf};
  static_assert(kWidth == 8, "one initialiser per partial");
  int i = 0;
  for (; i + kWidth <= n; i += kWidth)
    for (int k = 0; k < kWidth; ++k) part[k] = std::min(part[k], x[i + k]);
  for (int k = 0; i < n; ++i, ++k) part[k] = std::min(part[k], x[i]);
  float m = kInf;
  for (int k = 0; k < kWidth; ++k) m = std::min(m, part[k]);
  return m;
}

// Σ x[i] in the partials' order (not lane order: ConstLanes::sum and sum_over keep that).
template <class X>
float sum(const X& x, int n) {
  float part[kWidth] = {};
  int i = 0;
  for (; i + kWidth <= n; i += kWidth)
    for (int k = 0; k < kWidth; ++k) part[k] += x[i + k];
  for (int k = 0; i < n; ++i, ++k) part[k] += x[i];
  float s = 0.0f;
  for (int k = 0; k < kWidth; ++k) s += part[k];
  return s;
}

}  // namespace prizma::render::partial
