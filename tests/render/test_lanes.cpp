// The tracer's per-lane types (renderer/src/lanes.h): LaneArray values and Lanes views, and their
// element-wise expressions, which must give the bits of the loops they stand for.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <stdexcept>
#include <vector>

#include "../../renderer/src/lanes.h"

namespace prizma::render {
namespace {

std::vector<float> random_lanes(int n, std::uint32_t seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<float> u(-3.0f, 3.0f);
  std::vector<float> v(static_cast<std::size_t>(n));
  for (float& x : v) x = u(gen);
  return v;
}

bool same_bits(const float* a, const float* b, int n) {
  return std::memcmp(a, b, sizeof(float) * static_cast<std::size_t>(n)) == 0;
}

TEST(Lanes, LaneArrayCopiesItsUsedLanesOnly) {
  LaneArray<0> a(5);
  for (int i = 0; i < 5; ++i) a[i] = 1.5f * static_cast<float>(i);
  LaneArray<0> b(8, -1.0f);
  b = a;
  EXPECT_EQ(b.size(), 5);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(b[i], a[i]);
  // Lanes 5..7 of b are past its new size: the copy did not touch them.
  for (int i = 5; i < 8; ++i) EXPECT_EQ(b.data()[i], -1.0f);
  const LaneArray<0> c(a);
  EXPECT_EQ(c.size(), 5);
  EXPECT_TRUE(same_bits(c.data(), a.data(), 5));
  a[0] = 7.0f;  // a value: the copies do not change with it
  EXPECT_EQ(b[0], 0.0f);
  EXPECT_EQ(c[0], 0.0f);
}

TEST(Lanes, LaneArrayChecksItsSizeAgainstItsCapacity) {
  static_assert(LaneArray<0>::kCapacity == spectral::BinLayout::kMaxBins);
  static_assert(LaneArray<1>::kCapacity == 1);
  static_assert(alignof(LaneArray<0>) == 64);
  EXPECT_NO_THROW(static_cast<void>(LaneArray<0>(spectral::BinLayout::kMaxBins)));
  EXPECT_NO_THROW(static_cast<void>(LaneArray<0>(0)));
  EXPECT_THROW(static_cast<void>(LaneArray<0>(spectral::BinLayout::kMaxBins + 1)), std::length_error);
  EXPECT_THROW(static_cast<void>(LaneArray<0>(-1)), std::length_error);
  EXPECT_THROW(static_cast<void>(LaneArray<1>(2)), std::length_error);
  EXPECT_EQ(LaneArray<1>(1, 2.0f).size(), 1);
  const LaneArray<0> filled(3, 0.25f);
  EXPECT_EQ(filled.size(), 3);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(filled[i], 0.25f);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(filled.data()) % 64, 0u);
}

TEST(Lanes, ExpressionsOnValuesAndViewsGiveTheBitsOfTheLoop) {
  for (const int n : {1, 7, 8, 31, 64, 1024}) {
    const std::vector<float> wv = random_lanes(n, 1), tv = random_lanes(n, 2), fv = random_lanes(n, 3);
    std::vector<float> out_view = random_lanes(n, 4);
    std::vector<float> out_loop = out_view;
    const float k = 0.3f;
    // out += w·k·T, w a value and T a view; then w = max(0, 1 − w·f) · k and w *= f.
    LaneArray<0> w(n);
    for (int i = 0; i < n; ++i) w[i] = wv[i];
    const ConstLanes<0> T(tv.data(), n), f(fv.data(), n);
    Lanes<0>(out_view.data(), n) += w * k * T;
    LaneArray<0> x(n);
    x = lane_max(0.0f, 1.0f - w * f) * k;
    x *= f;
    x += lane_map([](float v) { return std::exp(-v); }, T);
    std::vector<float> x_loop(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
      out_loop[i] += wv[i] * k * tv[i];
      x_loop[i] = std::max(0.0f, 1.0f - wv[i] * fv[i]) * k;
      x_loop[i] *= fv[i];
      x_loop[i] += std::exp(-tv[i]);
    }
    EXPECT_TRUE(same_bits(out_view.data(), out_loop.data(), n)) << n << " lanes";
    EXPECT_TRUE(same_bits(x.data(), x_loop.data(), n)) << n << " lanes";
    // The reductions of a value are those of its view (partial sums in a fixed order).
    EXPECT_EQ(x.sum(), x.view().sum());
    EXPECT_EQ(x.max(), partial::max_from_zero(x_loop.data(), n));
    float dot = 0.0f;
    for (int i = 0; i < n; ++i) dot += wv[i] * tv[i];
    EXPECT_EQ(sum_over(w * T, n), dot);
  }
}

}  // namespace
}  // namespace prizma::render
