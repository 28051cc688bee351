// Procedural volumes: values at known points (voxel centres at (i + 0.5)/n·2 − 1) and the volume
// fractions of their shapes.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "prizma/render/volume.h"
#include "prizma/spectral/error.h"

namespace prizma::render {
namespace {

// Index of the voxel whose centre is nearest to coordinate c in [−1, 1] at resolution n.
int voxel(double c, int n) { return static_cast<int>(std::floor((c + 1.0) / 2.0 * n)); }

TEST(ProceduralVolume, CubeSphereValuesAtKnownPoints) {
  const int n = 128;
  const Volume v = make_procedural_volume("cube_sphere", n);
  EXPECT_EQ(v.dims, (std::array<int, 3>{n, n, n}));
  EXPECT_EQ(v.spacing, (std::array<double, 3>{1, 1, 1}));
  const int c = voxel(0.0, n);
  EXPECT_EQ(v.at(c, c, c), 255.0f);                               // centre: sphere
  EXPECT_EQ(v.at(voxel(0.45, n), c, c), 255.0f);                  // r ≈ 0.45 < 0.5
  EXPECT_EQ(v.at(voxel(0.6, n), c, c), 100.0f);                   // r ≈ 0.6: cube, outside the sphere
  EXPECT_EQ(v.at(voxel(0.6, n), voxel(0.6, n), voxel(-0.6, n)), 100.0f);  // cube corner region
  EXPECT_EQ(v.at(voxel(0.85, n), c, c), 0.0f);                    // |x| ≈ 0.85 > 0.8: outside
  EXPECT_EQ(v.at(0, 0, 0), 0.0f);
  EXPECT_EQ(v.at(n - 1, n - 1, n - 1), 0.0f);
}

TEST(ProceduralVolume, CubeSphereVolumeFractions) {
  // Continuous fractions of [−1, 1]³: sphere (4/3)π·0.5³/8 = 0.06545, cube 1.6³/8 − sphere = 0.4466.
  // Voxelisation moves each face by at most one voxel (2/n in coordinates) in total per axis, so the
  // cube fraction is off by at most 3·1.6²/8·(2/n) = 1.92/n and the sphere's by 4π·0.5²/8·(2/n) = 1.57/n.
  const int res = 128;
  const Volume v = make_procedural_volume("cube_sphere", res);
  double sphere = 0.0;
  double cube = 0.0;
  for (float x : v.values) {
    sphere += x == 255.0f;
    cube += x == 100.0f;
  }
  const double n = static_cast<double>(v.values.size());
  const double sphere_exact = 4.0 / 3.0 * std::numbers::pi * 0.125 / 8.0;
  EXPECT_NEAR(sphere / n, sphere_exact, 1.57 / res);
  EXPECT_NEAR((cube + sphere) / n, 1.6 * 1.6 * 1.6 / 8.0, 1.92 / res);
  EXPECT_GT(cube, 0.0);
}

TEST(ProceduralVolume, HomogeneousBoxIsOneEverywhere) {
  const Volume v = make_procedural_volume("homogeneous_box", 8);
  ASSERT_EQ(v.values.size(), 512u);
  for (float x : v.values) EXPECT_EQ(x, 1.0f);
}

TEST(ProceduralVolume, MetamerPairSpheresAndGap) {
  const int n = 64;
  const Volume v = make_procedural_volume("metamer_pair", n);
  const int c = voxel(0.0, n);
  EXPECT_EQ(v.at(voxel(-0.5, n), c, c), 100.0f);  // left sphere centre
  EXPECT_EQ(v.at(voxel(0.5, n), c, c), 200.0f);   // right sphere centre
  EXPECT_EQ(v.at(voxel(-0.2, n), c, c), 100.0f);  // inside the left sphere (r = 0.3)
  EXPECT_EQ(v.at(c, c, c), 0.0f);                 // the gap between them (|x| < 0.1)
  EXPECT_EQ(v.at(voxel(-0.5, n), voxel(0.5, n), c), 0.0f);  // beside the left sphere
  // Both spheres have the same volume.
  std::size_t left = 0;
  std::size_t right = 0;
  for (float x : v.values) {
    left += x == 100.0f;
    right += x == 200.0f;
  }
  EXPECT_EQ(left, right);
  EXPECT_GT(left, 0u);
}

TEST(ProceduralVolume, RejectsUnknownNameAndBadResolution) {
  EXPECT_THROW(make_procedural_volume("sphere_in_cube_typo", 16), spectral::InputError);
  EXPECT_THROW(make_procedural_volume("cube_sphere", 0), spectral::InputError);
  EXPECT_THROW(make_procedural_volume("cube_sphere", -4), spectral::InputError);
  EXPECT_THROW(make_procedural_volume("cube_sphere", 100000), spectral::InputError);
  EXPECT_EQ(procedural_volume_names().size(), 3u);
}

}  // namespace
}  // namespace prizma::render
