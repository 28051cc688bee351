// MajorantGrid and its DDA traversal; grid vs global majorant renders; empty space costs one step
// per cell.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

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

namespace prizma::render {

// The grid is built in parallel over rows of cells (majorant_grid.cpp): every builder (nearest
// voxels, trilinear value ranges, sparse block ranges, clip planes) gives the same cells bit for bit
// on one thread and on four, and the nearest builder's cells are the maxima over their own voxels.
namespace {

Medium uneven_medium() {
  Medium m;
  m.dims = {41, 23, 34};  // not multiples of the cell size: short last cells on every axis
  const std::size_t n = m.voxel_count();
  m.material.assign(n, Medium::kEmpty);
  m.density.assign(n, 0.0f);
  m.value.assign(n, 0.0f);
  m.materials = {testing::grey_material(0.5, 2.0), testing::grey_material(0.8, 7.0)};
  std::uint32_t state = 7;
  for (std::size_t v = 0; v < n; ++v) {
    state = state * 1664525u + 1013904223u;
    const float u = static_cast<float>(state >> 8) / 16777216.0f;
    m.value[v] = 300.0f * u;
    if (u < 0.3f) continue;  // empty
    m.material[v] = u < 0.7f ? 0 : 1;
    m.density[v] = u;
  }
  MaterialRule a, b;
  a.value_lo = 90;
  a.value_hi = 210;
  a.material = 0;
  b.value_lo = 210;
  b.value_hi = 300;
  b.material = 1;
  m.rules = {a, b};
  return m;
}

std::vector<float> cells_of(const MajorantGrid& g) {
  std::vector<float> out;
  for (int z = 0; z < g.cells()[2]; ++z)
    for (int y = 0; y < g.cells()[1]; ++y)
      for (int x = 0; x < g.cells()[0]; ++x) out.push_back(g.majorant(x, y, z));
  return out;
}

std::vector<float> built_on(int threads, const Medium& m, int cell_voxels) {
  tbb::task_arena arena(threads);
  std::vector<float> out;
  arena.execute([&] { out = cells_of(MajorantGrid(m, {2.0f, 7.0f}, cell_voxels)); });
  return out;
}

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

}  // namespace

TEST(MajorantGrid, ParallelBuildIsTheSameOnAnyThreadCount) {
  Medium m = uneven_medium();
  m.clip = {ClipPlane{Eigen::Vector3d(0.6, 0.0, 0.8), 0.1}};
  const std::vector<float> one = built_on(1, m, 8);
  ASSERT_EQ(one.size(), std::size_t{6 * 3 * 5});
  EXPECT_TRUE(same_bits(one, built_on(4, m, 8)));
  EXPECT_TRUE(same_bits(built_on(1, m, 4), built_on(4, m, 4)));
  EXPECT_TRUE(same_bits(built_on(1, m, 0), built_on(4, m, 0)));
  m.interpolation = Interpolation::Trilinear;
  EXPECT_TRUE(same_bits(built_on(1, m, 8), built_on(4, m, 8)));
  m.block_range.assign(static_cast<std::size_t>(6) * 3 * 5, {100.0f, 250.0f});
  m.block_range[17] = {0.0f, 50.0f};
  EXPECT_TRUE(same_bits(built_on(1, m, 8), built_on(4, m, 8)));
  EXPECT_TRUE(same_bits(built_on(1, m, 16), built_on(4, m, 16)));
}

TEST(MajorantGrid, ParallelNearestBuildHoldsEachCellsVoxelMaximum) {
  const Medium m = uneven_medium();
  const std::vector<float> sigma{2.0f, 7.0f};
  const MajorantGrid grid(m, sigma, 8);
  std::vector<float> want(static_cast<std::size_t>(6) * 3 * 5, 0.0f);
  for (int z = 0; z < m.dims[2]; ++z)
    for (int y = 0; y < m.dims[1]; ++y)
      for (int x = 0; x < m.dims[0]; ++x) {
        const std::size_t v = (static_cast<std::size_t>(z) * m.dims[1] + y) * m.dims[0] + x;
        if (m.material[v] == Medium::kEmpty) continue;
        float& c = want[(static_cast<std::size_t>(z / 8) * 3 + y / 8) * 6 + x / 8];
        c = std::max(c, m.density[v] * sigma[m.material[v]]);
      }
  EXPECT_TRUE(same_bits(cells_of(grid), want));
}

TEST(MajorantGrid, CellControlsAreTheLeastDensityOfOneMaterial) {
  // Residual ratio tracking's controls: a cell of one material gets its least density and the
  // residual (largest − least)·σt_max (one ulp up); a cell with an empty voxel or a second
  // material gets none, its residual the majorant.
  Medium m = medium_16();
  m.materials.push_back(testing::grey_material(0.5, 3.0));
  auto fill = [&](int cx, int cy, int cz, auto density_of) {
    for (int z = 8 * cz; z < 8 * cz + 8; ++z)
      for (int y = 8 * cy; y < 8 * cy + 8; ++y)
        for (int x = 8 * cx; x < 8 * cx + 8; ++x) {
          const std::size_t v = (static_cast<std::size_t>(z) * 16 + y) * 16 + x;
          m.material[v] = 0;
          m.density[v] = density_of(x, y, z);
        }
  };
  fill(0, 0, 0, [](int x, int, int) { return 1.0f + 0.25f * static_cast<float>(x % 5); });  // 1 … 2
  fill(1, 0, 0, [](int, int, int) { return 0.5f; });                                         // homogeneous
  fill(0, 1, 0, [](int, int, int) { return 1.0f; });
  m.material[(static_cast<std::size_t>(0) * 16 + 8) * 16 + 0] = Medium::kEmpty;  // one empty voxel
  fill(0, 0, 1, [](int, int, int) { return 1.0f; });
  m.material[(static_cast<std::size_t>(8) * 16 + 0) * 16 + 0] = 1;  // a second material
  const MajorantGrid grid(m, {2.0f, 3.0f}, 8);
  const CellControl& a = grid.control({0, 0, 0});
  EXPECT_EQ(a.material, 0);
  EXPECT_EQ(a.density, 1.0f);
  EXPECT_EQ(a.residual, std::nextafter(2.0f, 3.0f));  // (2 − 1)·2, one ulp up
  const CellControl& b = grid.control({1, 0, 0});
  EXPECT_EQ(b.material, 0);
  EXPECT_EQ(b.density, 0.5f);
  EXPECT_EQ(b.residual, 0.0f);  // homogeneous: no steps
  for (const auto& c : {std::array<int, 3>{0, 1, 0}, std::array<int, 3>{0, 0, 1}, std::array<int, 3>{1, 1, 1}}) {
    EXPECT_EQ(grid.control(c).material, CellControl::kNone);
    EXPECT_EQ(grid.control(c).residual, grid.majorant(c[0], c[1], c[2]));
  }
  EXPECT_FLOAT_EQ(grid.majorant(0, 0, 1), 3.0f);
}

}  // namespace prizma::render
