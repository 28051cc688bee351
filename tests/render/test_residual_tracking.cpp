// Residual ratio tracking (PathTracer::estimate_transmittance, the estimator of next-event
// estimation) against closed forms: a homogeneous slab's exp(−σ·d) exactly and without a step, a
// slab of two interleaved densities, a trilinear density gradient and a clipped slab within
// kSe standard errors (fixed seeds), lanes whose extinction spans a factor 10⁴.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "prizma/render/majorant_grid.h"
#include "prizma/render/path_tracer.h"
#include "prizma/render/rng.h"
#include "render_test_scenes.h"

namespace prizma::render {
namespace {

using testing::kSe;

constexpr int kLanes = 8;

// σt from 50 per unit at 400 nm down to 0.005 at 700 nm (linear): a spread of 10⁴ across lanes.
Material spread_material() {
  return testing::make_material(spectral::Spectrum::constant(0.5), spectral::Spectrum({400, 700}, {50.0, 0.005}),
                                spectral::Spectrum::constant(0.0));
}

std::vector<float> lane_wavelengths(int lanes) {
  std::vector<float> l(lanes);
  for (int i = 0; i < lanes; ++i) l[i] = lanes == 1 ? 550.0f : 400.0f + 300.0f * static_cast<float>(i) / (lanes - 1);
  return l;
}

double sigma_at(const Material& m, float lambda) { return m.sigma_t_per_unit.eval(lambda); }

// The mean and standard error per lane of `count` estimates along (origin, dir) up to t_max, and
// the shadow steps they took.
struct Estimates {
  std::vector<double> mean, se;
  double steps_per_estimate = 0.0;
};
Estimates estimate(const Scene& scene, int lanes, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                   double t_max, int count) {
  const PathTracer tracer(scene, 400.0, 700.0, true);
  PathScratch s;
  tracer.prepare(s, lanes);
  s.in.lambda_nm = lane_wavelengths(lanes);
  std::vector<double> sum(lanes, 0.0), sum2(lanes, 0.0);
  for (int k = 0; k < count; ++k) {
    Rng rng(11, static_cast<std::uint64_t>(k), 0);
    tracer.estimate_transmittance(origin, dir, t_max, rng, s);
    for (int i = 0; i < lanes; ++i) {
      const double t = s.work.transmittance[i];
      sum[i] += t;
      sum2[i] += t * t;
    }
  }
  Estimates e;
  for (int i = 0; i < lanes; ++i) {
    const double m = sum[i] / count;
    e.mean.push_back(m);
    e.se.push_back(std::sqrt(std::max(0.0, sum2[i] / count - m * m) / (count - 1)));
  }
  e.steps_per_estimate = static_cast<double>(s.counters.shadow_steps) / count;
  return e;
}

double path_length(const Scene& scene, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_max) {
  double t0, t1;
  if (!intersect_box(Ray{origin, dir}, scene.medium.bounds_min, scene.medium.bounds_max, t0, t1)) return 0.0;
  return std::max(0.0, std::min(t1, t_max) - t0);
}

TEST(ResidualTracking, HomogeneousSlabIsExactAndTakesNoSteps) {
  // One material at one density: every cell's control is the medium itself, μ̄r = 0, so the
  // estimate is exp(−σt·d) for every lane, with no random number. Through 2³ cells, obliquely.
  const Scene scene = testing::box_scene(spread_material(), 16);
  const Eigen::Vector3d origin(-0.1, 0.05, 1.0);
  const Eigen::Vector3d dir = Eigen::Vector3d(0.13, -0.07, -1.0).normalized();
  const double d = path_length(scene, origin, dir, 1e30);
  ASSERT_NEAR(d, Eigen::Vector3d(0.13, -0.07, -1.0).norm(), 1e-12);  // z from 0.5 to −0.5
  for (int lanes : {1, kLanes}) {
    const Estimates e = estimate(scene, lanes, origin, dir, 1e30, 16);
    EXPECT_EQ(e.steps_per_estimate, 0.0) << lanes;
    const std::vector<float> l = lane_wavelengths(lanes);
    for (int i = 0; i < lanes; ++i) {
      const double tau = sigma_at(scene.medium.materials[0], l[i]) * d;  // 0.005 … 50
      EXPECT_EQ(e.se[i], 0.0) << i;
      // Float optical depth summed over the cells: relative 10⁻⁵.
      EXPECT_NEAR(-std::log(e.mean[i]), tau, 1e-5 * tau + 1e-7) << "lane " << i << " of " << lanes;
    }
  }
}

TEST(ResidualTracking, TwoInterleavedDensitiesMatchBeerLambert) {
  // Layers of one voxel along z alternate density 1 and 3, so every cell holds both: control
  // d_c = 1 (σc = σt), residual μ̄r = (3 − 1)·max σt. A ray crossing four whole layers (two
  // pairs) at angle θ sees τ = σt·(1 + 3)·2·h / cos θ (h the layer's thickness).
  Scene scene = testing::box_scene(spread_material(), 40);
  const int n = 40;
  for (int z = 0; z < n; ++z)
    for (int i = 0; i < n * n; ++i) scene.medium.density[static_cast<std::size_t>(z) * n * n + i] = z % 2 ? 3.0f : 1.0f;
  const double h = 1.0 / n;
  const Eigen::Vector3d dir = Eigen::Vector3d(0.3, 0.2, 1.0).normalized();
  const double cos_theta = dir.z();
  const Eigen::Vector3d origin(0.01, 0.02, -0.5 + 8 * h);  // a layer's (and a cell's) boundary
  const double t_max = 4 * h / cos_theta;
  const int count = 20000;
  const Estimates e = estimate(scene, kLanes, origin, dir, t_max, count);
  const std::vector<float> l = lane_wavelengths(kLanes);
  for (int i = 0; i < kLanes; ++i) {
    const double exact = std::exp(-sigma_at(scene.medium.materials[0], l[i]) * 8.0 * h / cos_theta);
    EXPECT_NEAR(e.mean[i], exact, kSe * e.se[i] + 1e-7) << "lane " << i << " exact " << exact;
  }
  // Steps are drawn against the residual μ̄r = 2·50 (Poisson, mean μ̄r·t_max), not the majorant 3·50.
  const double mean_steps = 100.0 * t_max;
  EXPECT_NEAR(e.steps_per_estimate, mean_steps, kSe * std::sqrt(mean_steps / count) + 1e-4 * mean_steps);
}

TEST(ResidualTracking, TrilinearGradientMatchesItsIntegral) {
  // Trilinear values k at voxel layer k along z, one rule whose ramp gives density 1 + 0.1·v: the
  // density is linear in z between the voxel centres, so ∫ d dz over [−0.3, 0.3] is 0.6 times its
  // value at z = 0, 1 + 0.1·(0.5·16 − 0.5) = 1.75. Each cell's control is its least density.
  const Material mat = testing::make_material(spectral::Spectrum::constant(0.5), spectral::Spectrum({400, 700}, {4.0, 1.0}),
                                              spectral::Spectrum::constant(0.0));
  Scene scene = testing::box_scene(mat, 16);
  Medium& med = scene.medium;
  med.interpolation = Interpolation::Trilinear;
  MaterialRule rule;
  rule.material = 0;
  rule.density.values = {0.0, 15.0};
  rule.density.densities = {1.0, 2.5};
  med.rules = {rule};
  med.value.assign(med.voxel_count(), 0.0f);
  for (std::size_t v = 0; v < med.voxel_count(); ++v) {
    med.value[v] = static_cast<float>(v / 256);
    med.density[v] = static_cast<float>(rule.density.eval(med.value[v]));
  }
  const Eigen::Vector3d origin(0.05, -0.05, 0.3), dir(0, 0, -1);
  const int count = 20000;
  const Estimates e = estimate(scene, kLanes, origin, dir, 0.6, count);
  EXPECT_GT(e.steps_per_estimate, 0.1);  // a gradient is not homogeneous: residual steps are taken
  const std::vector<float> l = lane_wavelengths(kLanes);
  for (int i = 0; i < kLanes; ++i) {
    const double exact = std::exp(-sigma_at(mat, l[i]) * 0.6 * 1.75);
    EXPECT_NEAR(e.mean[i], exact, kSe * e.se[i] + 1e-7) << "lane " << i << " exact " << exact;
  }
}

TEST(ResidualTracking, ACutCellKeepsNoControl) {
  // The plane z = 0.1 cuts the upper cells (z from 0 to 0.5) of a homogeneous 16³ box: they keep
  // plain ratio tracking, the lower cells their exact control; a ray along −z sees medium over
  // z ∈ [−0.5, 0.1] only: τ = 0.6·σt. (A control kept in a cut cell would give 1.0·σt.)
  const Material mat = testing::make_material(spectral::Spectrum::constant(0.5), spectral::Spectrum({400, 700}, {4.0, 1.0}),
                                              spectral::Spectrum::constant(0.0));
  Scene scene = testing::box_scene(mat, 16);
  scene.medium.clip = {ClipPlane{Eigen::Vector3d(0, 0, 1), 0.1}};
  const PathTracer tracer(scene, 400.0, 700.0, true);
  EXPECT_EQ(tracer.grid().control({0, 0, 1}).material, CellControl::kNone);
  EXPECT_EQ(tracer.grid().control({0, 0, 0}).material, 0);
  EXPECT_EQ(tracer.grid().control({0, 0, 0}).residual, 0.0f);
  const int count = 20000;
  const Estimates e = estimate(scene, kLanes, Eigen::Vector3d(0.05, 0.05, 1.0), Eigen::Vector3d(0, 0, -1), 1e30, count);
  const std::vector<float> l = lane_wavelengths(kLanes);
  for (int i = 0; i < kLanes; ++i) {
    const double exact = std::exp(-sigma_at(mat, l[i]) * 0.6);
    EXPECT_NEAR(e.mean[i], exact, kSe * e.se[i] + 1e-7) << "lane " << i << " exact " << exact;
  }
}

}  // namespace
}  // namespace prizma::render
