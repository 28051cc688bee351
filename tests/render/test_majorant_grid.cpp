// MajorantGrid and its DDA traversal; grid vs global majorant renders; empty space costs one step
// per cell.
#include <gtest/gtest.h>

#include <cmath>

#include "prizma/render/majorant_grid.h"
#include "prizma/render/render.h"
#include "render_test_scenes.h"

namespace prizma::render {
namespace {

Medium medium_16() {
  Medium m;
  m.dims = {16, 16, 16};
  m.material.assign(m.voxel_count(), Medium::kEmpty);
  m.density.assign(m.voxel_count(), 0.0f);
  m.materials = {testing::grey_material(0.5, 2.0)};
  return m;
}

TEST(MajorantGrid, CellMaximaOverVoxels) {
  Medium m = medium_16();
  auto set = [&](int x, int y, int z, float d) {
    const std::size_t v = (static_cast<std::size_t>(z) * 16 + y) * 16 + x;
    m.material[v] = 0;
    m.density[v] = d;
  };
  set(0, 0, 0, 1.0f);
  set(7, 7, 7, 3.0f);   // same cell (0,0,0)
  set(8, 0, 15, 0.5f);  // cell (1,0,1)
  const MajorantGrid grid(m, {2.0f}, 8);
  EXPECT_EQ(grid.cells(), (std::array<int, 3>{2, 2, 2}));
  EXPECT_FLOAT_EQ(grid.majorant(0, 0, 0), 6.0f);
  EXPECT_FLOAT_EQ(grid.majorant(1, 0, 1), 1.0f);
  EXPECT_EQ(grid.majorant(1, 1, 1), 0.0f);
  EXPECT_FLOAT_EQ(grid.max_majorant(), 6.0f);
  const MajorantGrid global(m, {2.0f}, 0);
  EXPECT_EQ(global.cells(), (std::array<int, 3>{1, 1, 1}));
  EXPECT_FLOAT_EQ(global.majorant(0, 0, 0), 6.0f);
}

TEST(MajorantGrid, TraversalAlongAnAxisVisitsEveryCellInOrder) {
  Medium m = medium_16();
  const MajorantGrid grid(m, {2.0f}, 4);  // 4×4×4 cells of size 0.25
  const Ray ray{{-1.0, -0.3, 0.1}, {1, 0, 0}};
  double t0, t1;
  ASSERT_TRUE(intersect_box(ray, m.bounds_min, m.bounds_max, t0, t1));
  EXPECT_DOUBLE_EQ(t0, 0.5);
  EXPECT_DOUBLE_EQ(t1, 1.5);
  MajorantTraversal walk(grid, ray, t0, t1);
  MajorantTraversal::Segment seg;
  int k = 0;
  while (walk.next(seg)) {
    EXPECT_EQ(seg.cell, (std::array<int, 3>{k, 0, 2})) << k;
    EXPECT_NEAR(seg.t0, 0.5 + 0.25 * k, 1e-12);
    EXPECT_NEAR(seg.t1, 0.75 + 0.25 * k, 1e-12);
    ++k;
  }
  EXPECT_EQ(k, 4);
}

TEST(MajorantGrid, DiagonalTraversalIsContiguousAndConsistent) {
  Medium m = medium_16();
  const MajorantGrid grid(m, {2.0f}, 2);  // 8³ cells
  const Eigen::Vector3d dir = Eigen::Vector3d(0.7, -0.4, 0.59).normalized();
  const Ray ray{{-0.45, 0.4, -0.48}, dir};
  double t0, t1;
  ASSERT_TRUE(intersect_box(ray, m.bounds_min, m.bounds_max, t0, t1));
  MajorantTraversal walk(grid, ray, t0, t1);
  MajorantTraversal::Segment seg;
  double t = t0;
  std::array<int, 3> prev{-1, -1, -1};
  int count = 0;
  while (walk.next(seg)) {
    EXPECT_NEAR(seg.t0, t, 1e-12);
    EXPECT_GE(seg.t1, seg.t0);
    // The segment's midpoint lies in the reported cell.
    // (A ray through an edge or corner gives a zero-length segment in between: no midpoint test.)
    const Eigen::Vector3d p = ray.origin + 0.5 * (seg.t0 + seg.t1) * dir;
    if (seg.t1 - seg.t0 > 1e-9) {
      for (int a = 0; a < 3; ++a) EXPECT_EQ(static_cast<int>(std::floor((p[a] + 0.5) / 0.125)), seg.cell[a]);
    }
    // Consecutive cells share a face.
    if (count > 0) {
      int diff = 0;
      for (int a = 0; a < 3; ++a) diff += std::abs(seg.cell[a] - prev[a]);
      EXPECT_EQ(diff, 1);
    }
    prev = seg.cell;
    t = seg.t1;
    ++count;
  }
  EXPECT_NEAR(t, t1, 1e-12);
  EXPECT_GT(count, 8);
}

TEST(MajorantGrid, EmptySpaceCostsOneStepPerCell) {
  // Only one corner voxel holds medium; orthographic rays down the middle cross empty cells only.
  Scene s = testing::box_scene(testing::grey_material(0.8, 50.0), 32, 4, 4);
  std::fill(s.medium.material.begin(), s.medium.material.end(), Medium::kEmpty);
  s.medium.material[0] = 0;
  s.camera.ortho_height = 0.2;
  RenderStats grid_stats, flat_stats;
  const auto a = render(s, {}, &grid_stats);
  EXPECT_EQ(grid_stats.collisions, 0);
  // 32 voxels / 8 per cell = 4 cells along z per ray.
  EXPECT_EQ(grid_stats.majorant_cells, 4 * 4 * 4 * 4);
  s.settings.use_majorant_grid = false;
  const auto b = render(s, {}, &flat_stats);
  EXPECT_GT(flat_stats.collisions, 4 * 4 * 4 * 10);  // σ̄ = 50 over depth 1: ~50 null collisions per ray
  for (std::size_t k = 0; k < a.lights[0].data.size(); ++k) {
    EXPECT_EQ(a.lights[0].data[k], 1.0f);
    EXPECT_EQ(b.lights[0].data[k], 1.0f);
  }
}

TEST(MajorantGrid, GridAndGlobalMajorantAgreeWithinNoise) {
  using spectral::Spectrum;
  Scene s = testing::box_scene(testing::make_material(Spectrum({400.0, 700.0}, {0.9, 0.6}),
                                                      Spectrum({400.0, 700.0}, {6.0, 2.0}),
                                                      Spectrum::constant(0.3)),
                               16, 8, 128);
  testing::randomise_density(s, 0.0f, 1.0f);
  for (std::size_t v = 0; v < s.medium.voxel_count(); ++v)
    if ((v / 16) % 16 < 8) s.medium.density[v] = 0.0f;  // half the box empty
  s.lights.push_back(testing::directional_light("sun", {0, 1, 1}));
  RenderStats gs, fs;
  const auto grid = render(s, {}, &gs);
  s.settings.use_majorant_grid = false;
  const auto flat = render(s, {}, &fs);
  EXPECT_LT(gs.collisions, fs.collisions);
  for (int l = 0; l < 2; ++l) {
    const auto a = testing::pixel_average(grid, l), b = testing::pixel_average(flat, l);
    for (int i = 0; i < 6; ++i)
      EXPECT_NEAR(a.mean[i], b.mean[i], 4.0 * std::hypot(a.se[i], b.se[i])) << "light " << l << " bin " << i;
  }
}

}  // namespace
}  // namespace prizma::render
