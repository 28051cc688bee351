// The denoiser's kernels on synthetic planes with known truth and noise (fixed seeds): what must hold
// of any such filter (normalised, constant in → constant out, edges beyond the noise kept, noise
// reduced on smooth signals) and the determinism the file format relies on.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <array>
#include <cmath>
#include <numbers>
#include <numeric>
#include <string>
#include <vector>

#include "denoise_test_util.h"
#include "prizma/denoise/denoise.h"
#include "prizma/denoise/filter_weights.h"
#include "prizma/denoise/simd_target.h"
#include "prizma/spectral/error.h"

namespace prizma::denoise {
namespace {

constexpr int kW = 64, kH = 48;

TEST(FilterWeights, KernelsAreNonNegativeSumToOneAndStayInsideTheImage) {
  const auto g = test::noisy_guides(kW, kH, 0.05f, 1, [](int x, int) { return 1.0 + 0.01 * x; });
  const FilterWeights w = compute_weights(g);
  const int r = w.window_radius_px(), n = 2 * r + 1;
  for (auto [x, y] : {std::pair{0, 0}, {kW - 1, kH - 1}, {3, 20}, {31, 24}}) {
    const std::vector<float> k = w.kernel(x, y);
    ASSERT_EQ(static_cast<int>(k.size()), n * n);
    double sum = 0.0;
    for (int o = 0; o < n * n; ++o) {
      const int qx = x + o % n - r, qy = y + o / n - r;
      EXPECT_GE(k[o], 0.0f);
      if (qx < 0 || qy < 0 || qx >= kW || qy >= kH) {
        EXPECT_EQ(k[o], 0.0f) << x << "," << y << " offset " << o;
      }
      sum += k[o];
    }
    EXPECT_NEAR(sum, 1.0, 1e-6) << x << "," << y;
    EXPECT_GT(k[static_cast<std::size_t>(r * n + r)], 0.0f);  // the centre always counts
  }
}

TEST(FilterWeights, AConstantImageStaysConstant) {
  // Noisy guide, constant data: every kernel sums to 1, so the output is the constant to float
  // rounding: one rounding per weight and per addition of the 121 terms bounds the relative error
  // by 2·121·2^-24 = 1.4e-5.
  const auto g = test::noisy_guides(kW, kH, 0.1f, 2, [](int, int) { return 1.0; });
  const std::vector<float> flat(static_cast<std::size_t>(kW) * kH * 3, 0.75f);
  const std::vector<float> out = apply(compute_weights(g), flat, 3);
  for (float v : out) ASSERT_NEAR(v, 0.75f, 0.75f * 1.4e-5f);
}

TEST(FilterWeights, AZeroVariancePixelKeepsItsOwnValue) {
  // A noise-free background (every sample 0, variance 0) beside a faint, very noisy medium
  // (relative noise 1, so the centre test cannot cut it): the background keeps exactly 0 up to the
  // edge, and the medium is still averaged.
  auto g = test::noisy_guides(kW, kH, 0.3f, 11, [](int x, int) { return x < 32 ? 0.0 : 0.3; });
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < 32; ++x) {
      g.luminance.value[static_cast<std::size_t>(y) * kW + x] = 0.0f;
      g.luminance.variance[static_cast<std::size_t>(y) * kW + x] = 0.0f;
    }
  const FilterWeights w = compute_weights(g);
  const std::vector<float> out = apply(w, g.luminance.value, 1);
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < 32; ++x) ASSERT_EQ(out[static_cast<std::size_t>(y) * kW + x], 0.0f) << x << "," << y;
  const int r = w.window_radius_px(), n = 2 * r + 1;
  EXPECT_EQ(w.kernel(31, 20)[static_cast<std::size_t>(r * n + r)], 1.0f);   // the edge's background pixel
  EXPECT_LT(w.kernel(40, 20)[static_cast<std::size_t>(r * n + r)], 0.5f);   // the medium: averaged
}

// Mean over the rows of (filtered − truth) in column x.
double column_bias(const std::vector<float>& out, int x, double truth) {
  double s = 0.0;
  for (int y = 0; y < kH; ++y) s += out[static_cast<std::size_t>(y) * kW + x] - truth;
  return s / kH;
}

TEST(FilterWeights, AnEdgeFarBeyondTheNoiseIsKept) {
  // Two constant halves 20 standard errors apart: the columns either side of the edge must keep
  // their own level. Bound: 0.25 σ on the mean of a column of 48 pixels (the filtered noise alone
  // gives a standard error of that mean near σ/30; leaking 1.25 % of the other side's weight would
  // already give 0.25 σ).
  const double sigma = 0.05, lo = 1.0, hi = 1.0 + 20 * sigma;
  const auto g = test::noisy_guides(kW, kH, static_cast<float>(sigma), 3, [&](int x, int) { return x < kW / 2 ? lo : hi; });
  const std::vector<float> out = apply(compute_weights(g), g.luminance.value, 1);
  EXPECT_LT(std::abs(column_bias(out, kW / 2 - 1, lo)), 0.25 * sigma);
  EXPECT_LT(std::abs(column_bias(out, kW / 2, hi)), 0.25 * sigma);
}

TEST(FilterWeights, AThinLineFarBeyondTheNoiseIsKept) {
  // A one-pixel line 10 σ above a flat background (an MRI sulcus, a thin filament): its pixels may
  // average along the line but not with the background. Bound: the line keeps ≥ 90 % of its contrast.
  const double sigma = 0.05, contrast = 10 * sigma;
  const auto g = test::noisy_guides(kW, kH, static_cast<float>(sigma), 4,
                                    [&](int x, int) { return x == 20 ? 1.0 + contrast : 1.0; });
  const std::vector<float> out = apply(compute_weights(g), g.luminance.value, 1);
  EXPECT_GT(column_bias(out, 20, 1.0), 0.9 * contrast);
}

TEST(FilterWeights, AnIsolatedPixelFarBeyondTheNoiseIsKept) {
  // One pixel 10 σ above a flat background. Its patch matches its neighbours' in 48 of 49 pixels, so
  // the patch distance alone averages it away (to ~60 % of its contrast); the centre test (z > 3
  // standard errors) must keep it: ≥ 90 % of its contrast, averaged over 20 seeds.
  const double sigma = 0.05, contrast = 10 * sigma;
  double kept = 0.0;
  for (std::uint32_t seed = 0; seed < 20; ++seed) {
    const auto g = test::noisy_guides(kW, kH, static_cast<float>(sigma), 100 + seed,
                                      [&](int x, int y) { return x == 30 && y == 20 ? 1.0 + contrast : 1.0; });
    const std::vector<float> out = apply(compute_weights(g), g.luminance.value, 1);
    kept += (out[20 * kW + 30] - 1.0) / contrast / 20.0;
  }
  EXPECT_GT(kept, 0.9);
}

TEST(FilterWeights, AnEdgeOnlyAFeatureSeesIsKept) {
  // Flat noisy luminance; a noise-free feature (say, the depth of the first scattering) steps at
  // x = 32; the filtered values step there too (two materials of equal luminance, different
  // chroma: the luminance cannot separate them). With the feature the columns beside the step keep
  // their own side (≤ 2 % of the other side's weight); without it they mix (≥ 20 %).
  auto g = test::noisy_guides(kW, kH, 0.05f, 12, [](int, int) { return 1.0; });
  GuidePlane depth{"depth", {}, {}, false};
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) depth.value.push_back(x < kW / 2 ? 1.0f : 2.0f);
  std::vector<float> side(static_cast<std::size_t>(kW) * kH);
  for (std::size_t p = 0; p < side.size(); ++p) side[p] = p % kW < kW / 2 ? 0.0f : 1.0f;
  const std::vector<float> mixed = apply(compute_weights(g), side, 1);
  g.features.push_back(depth);
  const std::vector<float> kept = apply(compute_weights(g), side, 1);
  for (int y = 0; y < kH; ++y) {
    const std::size_t left = static_cast<std::size_t>(y) * kW + kW / 2 - 1, right = left + 1;
    EXPECT_LE(kept[left], 0.02f) << y;
    EXPECT_GE(kept[right], 0.98f) << y;
  }
  EXPECT_GE(column_bias(mixed, kW / 2 - 1, 0.0), 0.2);
}

TEST(FilterWeights, ReducesGaussianNoiseOnASmoothRamp) {
  // u = 1 + x/kW (a slope of σ/3.2 per pixel) with i.i.d. N(0, σ²): in the interior (window and
  // patch inside the image) the residual RMSE must fall below σ/4, a 16× variance reduction (an
  // 11×11 kernel of equal weights would give 121×; the variance-cancelled NL-means weights of pure
  // noise average about 0.8, which leaves ~100× minus what the slope and the centre test cost),
  // and the mean residual must stay within 3 standard errors of 0 (the ramp is linear, the
  // interior kernels symmetric in expectation: no bias).
  const double sigma = 0.05;
  auto truth = [](int x, int) { return 1.0 + static_cast<double>(x) / kW; };
  const auto g = test::noisy_guides(kW, kH, static_cast<float>(sigma), 5, truth);
  const FilterWeights w = compute_weights(g);
  const std::vector<float> out = apply(w, g.luminance.value, 1);
  const int m = w.window_radius_px() + w.options().patch_radius_px;
  double sq = 0.0, sum = 0.0;
  int count = 0;
  for (int y = m; y < kH - m; ++y)
    for (int x = m; x < kW - m; ++x) {
      const double e = out[static_cast<std::size_t>(y) * kW + x] - truth(x, y);
      sq += e * e;
      sum += e;
      ++count;
    }
  const double rmse = std::sqrt(sq / count);
  EXPECT_LT(rmse, sigma / 4) << "residual RMSE " << rmse;
  // Neighbouring outputs share most of their inputs: the mean's standard error is taken as
  // rmse / sqrt(count / 121), as if only one pixel per window were independent.
  EXPECT_LT(std::abs(sum / count), 3.0 * rmse / std::sqrt(count / 121.0)) << "mean residual " << sum / count;
}

TEST(FilterWeights, TheSureSelectionTakesTheWiderKWhereItIsBetter) {
  // Left half flat, right half stripes of 4 σ amplitude and a 6-pixel period, i.i.d. N(0, σ²): the
  // wide k (1.0) is the better filter of this image (it averages the flat half more and the stripes'
  // patches still tell them apart). Choosing per pixel by SURE must get most of that: its mean
  // squared error at least 20 % below the narrow k's alone (measured: 31 %), and never above it
  // on either half. With the selection broken (always the narrow k) the first bound fails.
  const double sigma = 0.05;
  auto truth = [&](int x, int y) { return x < kW / 2 ? 1.0 : 1.0 + 4 * sigma * std::sin(2 * std::numbers::pi * (x + y) / 6); };
  const auto g = test::noisy_guides(kW, kH, static_cast<float>(sigma), 5, truth);
  auto half_mse = [&](float wide) {
    DenoiseOptions o;
    o.patch_k_wide = wide;
    const std::vector<float> out = apply(compute_weights(g, o), g.luminance.value, 1);
    std::array<double, 2> e{0.0, 0.0};
    for (int y = 0; y < kH; ++y)
      for (int x = 0; x < kW; ++x) {
        const double d = out[static_cast<std::size_t>(y) * kW + x] - truth(x, y);
        e[x >= kW / 2] += d * d;
      }
    return e;
  };
  const auto narrow = half_mse(0.0f), selected = half_mse(1.0f);
  EXPECT_LT(selected[0] + selected[1], 0.8 * (narrow[0] + narrow[1]));
  EXPECT_LE(selected[0], narrow[0]);
  EXPECT_LE(selected[1], narrow[1]);
}

TEST(FilterWeights, TheSameBitsWhateverTheThreadCountAndTileSize) {
  const auto g = test::noisy_guides(kW + 7, kH + 3, 0.05f, 6, [](int x, int y) { return 1.0 + 0.3 * std::sin(0.2 * x + 0.1 * y); });
  std::vector<float> values(g.luminance.value.size() * 5);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = static_cast<float>((i * 7919) % 1000) * 1e-3f;
  std::vector<std::vector<float>> results;
  for (int threads : {1, 2, 4})
    for (int tile : {8, 32, 40}) {
      tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
      DenoiseOptions o;
      o.tile_size_px = tile;
      results.push_back(apply(compute_weights(g, o), values, 5));
    }
  for (std::size_t k = 1; k < results.size(); ++k) EXPECT_EQ(results[k], results[0]) << "run " << k;
}

TEST(FilterWeights, TheSameBitsOnEverySimdLevel) {
  // The inner loops use only IEEE per-lane operations (no fused multiply-add, an exponential of
  // their own): every level this CPU runs must give the baseline's bits, SURE choice included.
  const auto g = test::noisy_guides(kW, kH, 0.05f, 10, [](int x, int y) { return 1.0 + 0.3 * std::sin(0.2 * x + 0.1 * y); });
  std::vector<float> values(g.luminance.value.size() * 7);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = static_cast<float>((i * 7919) % 1000) * 1e-3f;
  const std::vector<std::string> targets = detail::simd_targets();
  ASSERT_FALSE(targets.empty());
  std::vector<float> baseline;
  for (const std::string& t : targets) {
    detail::force_simd_target(t);
    const std::vector<float> out = apply(compute_weights(g), values, 7);
    if (baseline.empty()) baseline = out;
    EXPECT_EQ(out, baseline) << "SIMD level " << t << " (first: " << targets.front() << ")";
  }
  detail::force_simd_target("");
}

TEST(FilterWeights, OnePixelsKernelIsTheOneItsTileUses) {
  const auto g = test::noisy_guides(kW, kH, 0.05f, 7, [](int x, int) { return x < 30 ? 1.0 : 1.5; });
  const FilterWeights w = compute_weights(g);
  std::vector<float> tile;
  const PixelRect rect{16, 8, 32, 32};
  w.tile_kernels(rect, tile);
  const int k = w.kernel_size();
  for (auto [x, y] : {std::pair{16, 8}, {29, 20}, {30, 39}, {47, 30}}) {
    const std::vector<float> one = w.kernel(x, y);
    for (int o = 0; o < k; ++o)
      ASSERT_EQ(one[o], tile[static_cast<std::size_t>(o) * rect.pixel_count() +
                             static_cast<std::size_t>(y - rect.y0) * rect.width + (x - rect.x0)])
          << x << "," << y << " offset " << o;
  }
}

TEST(FilterWeights, ApplyIsTheSumOverEachPixelsKernel) {
  // apply() against Σ_q W(p,q)·v(q) in double from kernel(), and the squared weights likewise.
  const auto g = test::noisy_guides(kW, kH, 0.05f, 8, [](int x, int y) { return 1.0 + 0.02 * x + 0.01 * y; });
  const FilterWeights w = compute_weights(g);
  std::vector<float> v(static_cast<std::size_t>(kW) * kH * 2);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = 0.5f + static_cast<float>((i * 104729) % 997) * 1e-3f;
  const std::vector<float> out = apply(w, v, 2), out2 = apply(w, v, 2, KernelPower::SquaredWeights);
  const int r = w.window_radius_px(), n = 2 * r + 1;
  for (auto [x, y] : {std::pair{0, 0}, {10, 10}, {63, 5}, {40, 47}}) {
    const std::vector<float> k = w.kernel(x, y);
    for (int c = 0; c < 2; ++c) {
      double s = 0.0, s2 = 0.0;
      for (int o = 0; o < n * n; ++o) {
        if (k[o] == 0.0f) continue;
        const std::size_t q = static_cast<std::size_t>(y + o / n - r) * kW + (x + o % n - r);
        s += static_cast<double>(k[o]) * v[2 * q + c];
        s2 += static_cast<double>(k[o]) * k[o] * v[2 * q + c];
      }
      const std::size_t i = 2 * (static_cast<std::size_t>(y) * kW + x) + c;
      EXPECT_NEAR(out[i], s, 1e-6 * s);
      EXPECT_NEAR(out2[i], s2, 1e-6 * s2);
    }
  }
}

TEST(FilterWeights, RefusesGuidesWithoutVarianceAndOptionsOutOfRange) {
  auto g = test::noisy_guides(8, 8, 0.05f, 9, [](int, int) { return 1.0; });
  DenoiseOptions o;
  o.window_radius_px = 16;
  try {
    compute_weights(g, o);
    FAIL() << "accepted window radius 16";
  } catch (const spectral::InputError& e) {
    EXPECT_STREQ(e.what(), "denoise options: window radius 16 is outside [1, 15]");
  }
  g.luminance.variance.clear();
  try {
    compute_weights(g);
    FAIL() << "accepted a luminance without variance";
  } catch (const spectral::InputError& e) {
    EXPECT_STREQ(e.what(), "denoise guide \"luminance\": no variance plane (the weights compare values against their noise)");
  }
}

}  // namespace
}  // namespace prizma::denoise
