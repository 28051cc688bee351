// Henyey–Greenstein sampling and evaluation, the random stream, the camera.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>
#include <vector>

#include "prizma/render/camera.h"
#include "prizma/render/phase.h"
#include "prizma/render/rng.h"
#include "prizma/spectral/error.h"

namespace prizma::render {
namespace {

// HG's CDF in cos θ: P(cos ≤ c) = (1 − g²)/(2g) · (1/√(1 + g² − 2gc) − 1/(1 + g)).
double hg_cdf(double c, double g) {
  if (std::abs(g) < 1e-3) return 0.5 * (c + 1.0);
  return (1.0 - g * g) / (2.0 * g) * (1.0 / std::sqrt(1.0 + g * g - 2.0 * g * c) - 1.0 / (1.0 + g));
}

TEST(TracerPhase, HgIsNormalised) {
  for (double g : {-0.95, -0.5, 0.0, 0.3, 0.9}) {
    // Midpoint rule over cos θ with 2π azimuth; accurate to ~1e-4 for |g| ≤ 0.95 at 200k cells.
    const int n = 200000;
    double sum = 0;
    for (int k = 0; k < n; ++k) sum += hg_phase(static_cast<float>(-1.0 + (k + 0.5) * 2.0 / n), static_cast<float>(g));
    EXPECT_NEAR(sum * 2.0 / n * 2.0 * std::numbers::pi, 1.0, 2e-3) << g;
  }
}

TEST(TracerPhase, SampledCosinesFollowHg) {
  // Kolmogorov–Smirnov against the analytic CDF (critical value 1.95/√N at the 0.1 % level) and the
  // mean cosine equal to g within 4 standard errors, including |g| → 1.
  for (double g : {-0.999, -0.9, -0.5, 0.0, 0.0005, 0.5, 0.9, 0.999}) {
    Rng rng(11, 0, static_cast<std::uint64_t>(std::lround((g + 1.0) * 1e4)));
    const int n = 50000;
    std::vector<double> c(n);
    double sum = 0, sum_sq = 0;
    for (int k = 0; k < n; ++k) {
      c[k] = hg_sample_cos(static_cast<float>(g), rng.uniform());
      ASSERT_TRUE(c[k] >= -1.0 && c[k] <= 1.0);
      sum += c[k];
      sum_sq += c[k] * c[k];
    }
    const double mean = sum / n;
    const double se = std::sqrt(std::max(0.0, sum_sq / n - mean * mean) / n);
    EXPECT_NEAR(mean, g, 4.0 * se + 1e-5) << "g " << g;
    std::sort(c.begin(), c.end());
    // The sampler returns float cosines: near the lobe's peak for |g| = 0.999 one float step of cos θ
    // moves the CDF by up to ~0.06, so the KS bound adds the largest CDF step across one float ulp.
    double d = 0, resolution = 0;
    for (int k = 0; k < n; ++k) {
      const double f = hg_cdf(c[k], g);
      d = std::max({d, std::abs(f - static_cast<double>(k) / n), std::abs(f - static_cast<double>(k + 1) / n)});
      const auto cf = static_cast<float>(c[k]);
      resolution = std::max({resolution, std::abs(hg_cdf(std::nextafter(cf, 2.0f), g) - f),
                             std::abs(f - hg_cdf(std::nextafter(cf, -2.0f), g))});
    }
    EXPECT_LT(d, 1.95 / std::sqrt(n) + resolution) << "g " << g;
    if (std::abs(g) < 0.95) {
      EXPECT_LT(resolution, 1e-3) << "g " << g;
    }
  }
}

TEST(TracerPhase, DirectionAroundHasTheRequestedCosine) {
  const Eigen::Vector3d w = Eigen::Vector3d(0.2, -0.9, 0.4).normalized();
  for (double c : {-1.0, -0.3, 0.0, 0.7, 1.0}) {
    const Eigen::Vector3d d = direction_around(w, c, 0.37);
    EXPECT_NEAR(d.norm(), 1.0, 1e-12);
    EXPECT_NEAR(d.dot(w), c, 1e-12);
  }
  const Eigen::Vector3d down(0, 0, -1);
  EXPECT_NEAR(direction_around(down, 0.5, 0.1).dot(down), 0.5, 1e-12);
}

TEST(TracerPhase, RngStreamsDifferAndStayInTheOpenInterval) {
  std::set<std::uint32_t> firsts;
  for (std::uint64_t p = 0; p < 64; ++p)
    for (std::uint64_t s = 0; s < 64; ++s) firsts.insert(Rng(1, p, s).next_u32());
  EXPECT_GT(firsts.size(), 4090u);  // 4096 streams; a 32-bit collision is very unlikely
  // VPT's hash gave (x, y) and (x + 47, y − 19) the same stream; pixels here are independent keys.
  EXPECT_NE(Rng(1, 100, 0).next_u32(), Rng(1, 100 + 47 - 19 * 256, 0).next_u32());
  Rng r(5, 6, 7);
  for (int k = 0; k < 100000; ++k) {
    const float u = r.uniform();
    ASSERT_GT(u, 0.0f);
    ASSERT_LT(u, 1.0f);
    const double v = r.uniform_double();
    ASSERT_GT(v, 0.0);
    ASSERT_LT(v, 1.0);
  }
  EXPECT_EQ(Rng(3, 4, 5).next_u32(), Rng(3, 4, 5).next_u32());
}

TEST(TracerPhase, CameraRays) {
  Camera cam;
  cam.type = CameraType::Orthographic;
  cam.position = {0, 0, 2};
  cam.look_at = {0, 0, 0};
  cam.ortho_height = 2.0;
  cam.width = 4;
  cam.height = 2;
  const CameraModel ortho(cam);
  const Ray centre = ortho.generate(2.0, 1.0);
  EXPECT_NEAR((centre.origin - Eigen::Vector3d(0, 0, 2)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((centre.direction - Eigen::Vector3d(0, 0, -1)).norm(), 0.0, 1e-12);
  const Ray corner = ortho.generate(0.0, 0.0);  // top-left: x = −2 (aspect 2), y = +1
  EXPECT_NEAR((corner.origin - Eigen::Vector3d(-2, 1, 2)).norm(), 0.0, 1e-12);
  cam.type = CameraType::Perspective;
  cam.fov_y_deg = 90.0;
  const Ray top = CameraModel(cam).generate(2.0, 0.0);
  EXPECT_NEAR((top.direction - Eigen::Vector3d(0, 1, -1).normalized()).norm(), 0.0, 1e-12);
  cam.look_at = cam.position;
  EXPECT_THROW(CameraModel{cam}, spectral::InputError);
  cam.look_at = {0, 0, 0};
  cam.up = {0, 0, 1};
  EXPECT_THROW(CameraModel{cam}, spectral::InputError);
}

}  // namespace
}  // namespace prizma::render
