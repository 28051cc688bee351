// Trilinear interpolation with post-classification (issue 13 part 3): the interpolated value, the
// classification at a point, the majorant grid's bound over every point of a cell, and renders of
// nearest against trilinear media.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "prizma/render/majorant_grid.h"
#include "prizma/render/path_tracer.h"
#include "prizma/render/render.h"
#include "prizma/render/transfer_function.h"
#include "prizma/spectral/error.h"
#include "render_test_scenes.h"
#include "test_scene_util.h"

namespace prizma::render {
namespace {

using spectral::Spectrum;

Material grey(const std::string& name, double albedo, double sigma_t) {
  Material m = testing::grey_material(albedo, sigma_t);
  m.name = name;
  return m;
}

// A scene around a medium built from `vol` and `tf` with trilinear interpolation.
Scene scene_of(const Volume& vol, const TransferFunction& tf, Interpolation interp) {
  Scene s = testing::box_scene(grey("unused", 0.5, 1.0));
  s.medium = build_medium(vol, tf, "test", interp);
  return s;
}

// Voxel centre (i + 0.5)/n in the unit box [−0.5, 0.5]³ (n voxels per axis).
double centre(int i, int n) { return (i + 0.5) / n - 0.5; }

TEST(Interpolation, TrilinearReproducesALinearRampExactly) {
  // Values a + b·x + c·y + d·z at the voxel centres, one material whose density is the value itself
  // (ramp [[0, 0], [100, 100]]): between the first and last voxel centres the interpolated density
  // is exactly that linear function (trilinear interpolation is exact for affine functions).
  const int n = 9;
  Volume vol;
  vol.dims = {n, n, n};
  vol.source = "ramp";
  auto f = [](double x, double y, double z) { return 50.0 + 20.0 * x - 30.0 * y + 40.0 * z; };
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) vol.values.push_back(static_cast<float>(f(centre(x, n), centre(y, n), centre(z, n))));
  TransferFunction tf;
  tf.materials = {grey("m", 0.5, 1.0)};
  MaterialRule r;
  r.density.values = {0.0, 100.0};
  r.density.densities = {0.0, 100.0};
  tf.rules = {r};
  const Scene s = scene_of(vol, tf, Interpolation::Trilinear);
  const PathTracer tracer(s, 400, 700, true);
  std::mt19937 gen(5);
  const double lo = centre(0, n), hi = centre(n - 1, n);
  std::uniform_real_distribution<double> u(lo, hi);
  for (int k = 0; k < 20000; ++k) {
    const Eigen::Vector3d p(u(gen), u(gen), u(gen));
    std::uint16_t m;
    float d;
    tracer.lookup(p, m, d);
    ASSERT_EQ(m, 0);
    ASSERT_NEAR(d, f(p.x(), p.y(), p.z()), 2e-4) << p.transpose();
  }
  // At a voxel centre it is the voxel's value; beyond the outermost centres it is clamped to the edge.
  std::uint16_t m;
  float d;
  tracer.lookup({centre(2, n), centre(3, n), centre(4, n)}, m, d);
  EXPECT_NEAR(d, vol.at(2, 3, 4), 1e-5);
  tracer.lookup({0.499, centre(3, n), centre(4, n)}, m, d);
  EXPECT_NEAR(d, vol.at(n - 1, 3, 4), 1e-4);
  // Nearest: the voxel's own value, constant over the voxel.
  const Scene sn = scene_of(vol, tf, Interpolation::Nearest);
  const PathTracer nearest(sn, 400, 700, true);
  nearest.lookup({centre(2, n) + 0.04, centre(3, n) - 0.04, centre(4, n)}, m, d);
  EXPECT_FLOAT_EQ(d, vol.at(2, 3, 4));
}

TEST(Interpolation, PostClassificationPassesThroughMaterialsBetweenVoxelValues) {
  // Two voxels, 0 and 200, and a material only on [90, 110]: no voxel holds it (nearest never shows
  // it), but interpolation passes through it between the two centres (post-classification, as VPT
  // does with its texture lookups); a non-finite voxel makes every point touching it empty.
  Volume vol;
  vol.dims = {2, 1, 1};
  vol.values = {0.0f, 200.0f};
  vol.source = "pair";
  TransferFunction tf;
  tf.materials = {grey("thin", 0.5, 1.0)};
  MaterialRule r;
  r.value_lo = 90.0;
  r.value_hi = 110.0;
  tf.rules = {r};
  Scene s = scene_of(vol, tf, Interpolation::Trilinear);
  const PathTracer tracer(s, 400, 700, true);
  std::uint16_t m;
  float d;
  tracer.lookup({0.0, 0.0, 0.0}, m, d);  // halfway: value 100
  EXPECT_EQ(m, 0);
  EXPECT_EQ(d, 1.0f);
  tracer.lookup({-0.2, 0.0, 0.0}, m, d);  // value 40
  EXPECT_EQ(m, Medium::kEmpty);
  EXPECT_GT(tracer.grid().max_majorant(), 0.0f);  // the grid sees the material between the voxels
  const Scene sn = scene_of(vol, tf, Interpolation::Nearest);
  const PathTracer nearest(sn, 400, 700, true);
  EXPECT_EQ(nearest.grid().max_majorant(), 0.0f);
  s.medium.value[1] = std::numeric_limits<float>::quiet_NaN();
  const PathTracer with_nan(s, 400, 700, true);
  with_nan.lookup({0.0, 0.0, 0.0}, m, d);
  EXPECT_EQ(m, Medium::kEmpty);
}

TEST(Interpolation, MajorantBoundsSigmaTAtEveryPoint) {
  // A random volume (values 0–255, some NaN) classified by overlapping, non-monotone rules with
  // density ramps: at 200 000 random points σt(p) = density × the material's largest σt never
  // exceeds the majorant of the cell holding p, for macrocells of 4 voxels and for one global cell.
  const int n = 24;
  Volume vol;
  vol.dims = {n, n - 3, n + 5};
  vol.source = "random";
  std::mt19937 gen(17);
  std::uniform_real_distribution<float> val(0.0f, 255.0f);
  for (std::size_t k = 0; k < vol.voxel_count(); ++k)
    vol.values.push_back(k % 97 == 0 ? std::numeric_limits<float>::quiet_NaN() : (k % 5 == 0 ? 0.0f : val(gen)));
  // Sparse bright spots: most voxels dark, so cells differ.
  for (std::size_t k = 0; k < vol.voxel_count(); ++k)
    if (k % 7 != 0 && std::isfinite(vol.values[k])) vol.values[k] *= 0.2f;
  TransferFunction tf;
  tf.materials = {grey("a", 0.5, 3.0), grey("b", 0.9, 40.0), grey("c", 0.2, 7.0)};
  MaterialRule ra, rb, rc;
  ra.value_lo = 10.0;
  ra.value_hi = 60.0;
  ra.material = 0;
  ra.density.values = {10.0, 30.0, 60.0};
  ra.density.densities = {0.0, 2.5, 0.5};
  rb.value_lo = 100.0;
  rb.value_hi = 120.0;
  rb.material = 1;  // a thin, dense band: reached only between voxel values
  rc.value_lo = 50.0;
  rc.value_hi = 255.0;
  rc.material = 2;
  rc.density.values = {150.0, 255.0};
  rc.density.densities = {1.0, 3.0};
  tf.rules = {ra, rb, rc};
  const Scene s = scene_of(vol, tf, Interpolation::Trilinear);
  const std::vector<float> sigma_max = {3.0f, 40.0f, 7.0f};
  const PathTracer tracer(s, 400, 700, true);
  for (int cell_voxels : {4, MajorantGrid::kCellVoxels, 0}) {
    const MajorantGrid own(s.medium, sigma_max, cell_voxels);
    // kCellVoxels: the tracer's own grid (its bounds carry one more float ulp of σt).
    const MajorantGrid& grid = cell_voxels == MajorantGrid::kCellVoxels ? tracer.grid() : own;
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int occupied = 0;
    for (int k = 0; k < 200000; ++k) {
      Eigen::Vector3d p;
      std::array<int, 3> cell{};
      for (int a = 0; a < 3; ++a) {
        p[a] = s.medium.bounds_min[a] + u(gen) * (s.medium.bounds_max[a] - s.medium.bounds_min[a]);
        cell[a] = std::clamp(static_cast<int>(std::floor((p[a] - grid.bounds_min()[a]) / grid.cell_size()[a])), 0,
                             grid.cells()[a] - 1);
      }
      std::uint16_t m;
      float d;
      tracer.lookup(p, m, d);
      if (m == Medium::kEmpty) continue;
      ++occupied;
      ASSERT_LE(d * sigma_max[m], grid.majorant(cell[0], cell[1], cell[2]))
          << "cells of " << cell_voxels << ": point " << p.transpose() << " material " << m << " density " << d;
    }
    EXPECT_GT(occupied, 20000);
  }
}

TEST(Interpolation, TrilinearFurnaceIsExactlyOneAndDiffersFromNearest) {
  // A smooth 8³ field rendered both ways: the furnace stays exactly 1 with trilinear media (analog
  // tracking, albedo 1), and the absorbing images differ (the medium is not the same).
  const int n = 8;
  Volume vol;
  vol.dims = {n, n, n};
  vol.source = "blob";
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const double r2 = std::pow(centre(x, n), 2) + std::pow(centre(y, n), 2) + std::pow(centre(z, n), 2);
        vol.values.push_back(static_cast<float>(255.0 * std::exp(-8.0 * r2)));
      }
  TransferFunction tf;
  tf.materials = {grey("white", 1.0, 6.0)};
  MaterialRule r;
  r.value_lo = 40.0;
  r.density.values = {40.0, 255.0};
  r.density.densities = {0.2, 2.0};
  tf.rules = {r};
  Scene s = scene_of(vol, tf, Interpolation::Trilinear);
  s.camera.ortho_height = 1.2;
  const auto furnace = render(s);  // named: a range-for over a temporary's member would dangle
  for (float v : furnace.lights[0].data) ASSERT_EQ(v, 1.0f);
  tf.materials = {grey("black", 0.0, 6.0)};
  Scene a = scene_of(vol, tf, Interpolation::Trilinear), b = scene_of(vol, tf, Interpolation::Nearest);
  const auto ia = render(a), ib = render(b);
  double diff = 0.0;
  for (std::size_t k = 0; k < ia.lights[0].data.size(); ++k) diff += std::abs(ia.lights[0].data[k] - ib.lights[0].data[k]);
  EXPECT_GT(diff, 0.1);
}

TEST(Interpolation, SceneFieldDefaultsToTrilinear) {
  testing::ScratchDir dir;
  auto scene = [&](const std::string& field) {
    return dir.write("s.json", R"({"volume": {"type": "procedural", "name": "cube_sphere", "resolution": 8)" + field +
                                   R"(}, "materials": [{"range": [50, 255], "albedo": 0.5, "extinction": 2}],
                                   "lights": [{"name": "env", "direction": [0, 0, 0]}]})");
  };
  const Scene def = load_scene(scene(""));
  EXPECT_EQ(def.medium.interpolation, Interpolation::Trilinear);
  EXPECT_EQ(def.medium.value.size(), def.medium.voxel_count());
  EXPECT_EQ(def.medium.rules.size(), 1u);
  EXPECT_EQ(load_scene(scene(R"(, "interpolation": "trilinear")")).medium.interpolation, Interpolation::Trilinear);
  const Scene near = load_scene(scene(R"(, "interpolation": "nearest")"));
  EXPECT_EQ(near.medium.interpolation, Interpolation::Nearest);
  EXPECT_TRUE(near.medium.value.empty());
  try {
    load_scene(scene(R"(, "interpolation": "cubic")"));
    ADD_FAILURE() << "no error";
  } catch (const spectral::InputError& e) {
    EXPECT_NE(std::string(e.what()).find(R"(volume.interpolation: must be "trilinear" or "nearest" (got "cubic"))"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace prizma::render
