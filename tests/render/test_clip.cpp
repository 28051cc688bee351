// Cut-away planes (issue 13 part 6): the medium is removed where dot(normal, p) > offset. Checked
// against Beer–Lambert of the thickness that remains (absolute closed form, 3 standard errors, fixed
// seeds), the majorant grid's zeroed cells, and the scene file's fields and errors.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "prizma/render/majorant_grid.h"
#include "prizma/render/render.h"
#include "prizma/spectral/error.h"
#include "render_test_scenes.h"
#include "test_scene_util.h"

namespace prizma::render {
namespace {

using testing::box_scene;
using testing::grey_material;
using testing::pixel_average;
using testing::ScratchDir;

constexpr double kSe = 3.0;  // tolerance in standard errors (fixed seeds)

ClipPlane plane(Eigen::Vector3d n, double offset) {
  ClipPlane p;
  p.normal = n.normalized();
  p.offset = offset;
  return p;
}

TEST(Clip, SlabClippedToPartOfItsThicknessGivesBeerLambertOfTheRest) {
  // The unit box of σt = 2.5, purely absorbing, seen along −z over depth 1 (z from 0.5 to −0.5).
  // Each case removes part of it; every camera ray then crosses `thickness` of medium, and the
  // environment layer is e^{−σt·thickness} exactly.
  struct Case {
    std::vector<ClipPlane> clip;
    double thickness;
    const char* what;
  };
  const std::vector<Case> cases = {
      {{plane({0, 0, 1}, 0.0)}, 0.5, "z > 0 removed: half"},
      {{plane({0, 0, -1}, 0.13)}, 0.63, "z < −0.13 removed (off the voxel and cell faces)"},
      {{plane({0, 0, 1}, 0.3), plane({0, 0, -1}, 0.1)}, 0.4, "two planes: −0.1 ≤ z ≤ 0.3 kept"},
      {{plane({0, 0, 1}, 0.7)}, 1.0, "plane outside the box: nothing removed"},
  };
  for (Interpolation ip : {Interpolation::Nearest, Interpolation::Trilinear}) {
    for (const Case& c : cases) {
      SCOPED_TRACE(c.what);
      Scene s = box_scene(grey_material(0.0, 2.5), 16, 4, 512);
      if (ip == Interpolation::Trilinear) {
        s.medium.interpolation = ip;
        s.medium.value.assign(s.medium.voxel_count(), 1.0f);
        MaterialRule r;
        r.material = 0;
        s.medium.rules = {r};
      }
      s.medium.clip = c.clip;
      const double expected = std::exp(-2.5 * c.thickness);
      for (std::uint64_t seed : {1, 2, 3}) {
        s.settings.seed = seed;
        const auto env = pixel_average(render(s), 0);
        for (std::size_t b = 0; b < env.mean.size(); ++b) {
          EXPECT_NEAR(env.mean[b], expected, kSe * env.se[b]) << "seed " << seed << " bin " << b;
          EXPECT_GT(env.se[b], 0.0);
        }
      }
    }
  }
}

TEST(Clip, ScatteringSlabClippedEqualsAThinnerSlab) {
  // A scattering slab (albedo 0.9, σt 4) with z > 0 cut away against the same slab built only in
  // z ≤ 0 (voxels of the upper half empty): the same medium, so the same image within noise.
  Scene clipped = box_scene(grey_material(0.9, 4.0), 8, 4, 256);
  clipped.lights.push_back(testing::directional_light("sun", Eigen::Vector3d(0.3, 0.2, 1.0).normalized()));
  Scene thin = clipped;
  clipped.medium.clip = {plane({0, 0, 1}, 0.0)};
  for (int z = 4; z < 8; ++z)
    for (int i = 0; i < 64; ++i) thin.medium.material[static_cast<std::size_t>(z) * 64 + i] = Medium::kEmpty;
  for (std::uint64_t seed : {4, 5}) {
    clipped.settings.seed = seed;
    thin.settings.seed = seed + 100;
    const auto a = render(clipped), b = render(thin);
    for (int light = 0; light < 2; ++light) {
      const auto ea = pixel_average(a, light), eb = pixel_average(b, light);
      for (std::size_t k = 0; k < ea.mean.size(); ++k)
        EXPECT_NEAR(ea.mean[k], eb.mean[k], kSe * std::hypot(ea.se[k], eb.se[k])) << "light " << light << " bin " << k;
    }
  }
}

TEST(Clip, MajorantGridZeroesOnlyCellsWhollyCutAway) {
  Scene s = box_scene(grey_material(0.5, 3.0), 32);
  s.medium.clip = {plane({1, 1, 0}, 0.1)};
  const std::vector<float> sigma_t_max{3.0f};
  const MajorantGrid g(s.medium, sigma_t_max), full(box_scene(grey_material(0.5, 3.0), 32).medium, sigma_t_max);
  int zero = 0;
  for (int z = 0; z < 4; ++z)
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 4; ++x) {
        // Cell (x, y) spans [−0.5 + x/4, −0.25 + x/4]; its lowest x + y corner decides.
        const double least = (-0.5 + x / 4.0) + (-0.5 + y / 4.0);
        const bool cut = least / std::sqrt(2.0) > 0.1;
        EXPECT_EQ(g.majorant(x, y, z), cut ? 0.0f : full.majorant(x, y, z)) << x << " " << y << " " << z;
        zero += cut;
      }
  EXPECT_GT(zero, 0);
}

// A scene file in `dir` of a 4³ homogeneous box with the clip planes `clip` (JSON).
std::filesystem::path clip_scene(const ScratchDir& dir, const std::string& clip) {
  return dir.write("s.json", R"({"volume": {"type": "procedural", "name": "homogeneous_box", "resolution": 4, "clip": )" +
                                 clip + R"(}, "materials": [{"albedo": 0.5, "extinction": 1}], "lights": [{"name": "env", "direction": [0, 0, 0]}]})");
}

TEST(Clip, SceneFieldsAndErrors) {
  ScratchDir dir;
  auto scene = [&](const std::string& clip) { return clip_scene(dir, clip); };
  const Scene s = load_scene(scene(R"([{"normal": [0, 0, 2], "offset": 0.5}, {"normal": [1, 0, 0]}])"));
  ASSERT_EQ(s.medium.clip.size(), 2u);
  EXPECT_DOUBLE_EQ(s.medium.clip[0].normal.z(), 1.0);  // normalised with its offset: 2z > 0.5 ⇔ z > 0.25
  EXPECT_DOUBLE_EQ(s.medium.clip[0].offset, 0.25);
  EXPECT_DOUBLE_EQ(s.medium.clip[1].offset, 0.0);  // offset defaults to 0
  auto expect_error = [&](const std::string& clip, const std::string& words) {
    try {
      load_scene(scene(clip));
      ADD_FAILURE() << clip;
    } catch (const spectral::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  expect_error(R"({"normal": [0, 0, 1]})", "volume.clip: must be an array of planes");
  expect_error(R"([{"normal": [0, 0, 0]}])", "volume.clip[0].normal: must not be the zero vector");
  expect_error(R"([{"offset": 1}])", "volume.clip[0].normal: is required");
  expect_error(R"([{"normal": [0, 1]}])", "volume.clip[0].normal: must be an array of 3 numbers");
  expect_error(R"([{"normal": [0, 0, 1], "offset": "x"}])", "volume.clip[0].offset: must be a number");
  expect_error(R"([{"normal": [0, 0, 1], "side": 1}])", "volume.clip[0].side: unknown field");
}

// issue 21: a normal of norm 1e-300 (the norm underflows to 0) or 1e300 (overflows to inf) was
// refused as "the zero vector"; scaled by its largest component first, it keeps its plane exactly
// as written, an offset that becomes ±inf included (1e-300·z > 1e10 holds for no finite point).
TEST(Clip, TinyAndHugeNormalsKeepTheirPlane) {
  ScratchDir dir;
  auto scene = [&](const std::string& clip) { return clip_scene(dir, clip); };
  const Scene s = load_scene(scene(R"([{"normal": [1e-300, 0, 0], "offset": 1e-301},
                                       {"normal": [1e300, 1e300, 0], "offset": 0},
                                       {"normal": [0, 0, 1e-300], "offset": 1e10}])"));
  ASSERT_EQ(s.medium.clip.size(), 3u);
  EXPECT_EQ(s.medium.clip[0].normal, Eigen::Vector3d(1, 0, 0));
  EXPECT_DOUBLE_EQ(s.medium.clip[0].offset, 0.1);  // x > 0.1 removed
  EXPECT_TRUE(s.medium.clip[1].normal.isApprox(Eigen::Vector3d(1, 1, 0).normalized()));
  EXPECT_EQ(s.medium.clip[1].offset, 0.0);
  EXPECT_EQ(s.medium.clip[2].normal, Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(s.medium.clip[2].offset, std::numeric_limits<double>::infinity());
  EXPECT_FALSE(s.medium.clipped(Eigen::Vector3d(0.05, -0.2, 0.4)));
  EXPECT_TRUE(s.medium.clipped(Eigen::Vector3d(0.15, -0.4, 0.0)));   // x > 0.1
  EXPECT_TRUE(s.medium.clipped(Eigen::Vector3d(0.05, 0.1, 0.0)));    // x + y > 0
  // The reverse: −1e-300·z > −1e10 holds for every finite point, so everything is cut away.
  const Scene all = load_scene(scene(R"([{"normal": [0, 0, -1e-300], "offset": -1e10}])"));
  EXPECT_TRUE(all.medium.clipped(Eigen::Vector3d(0, 0, 0.5)));
}

}  // namespace
}  // namespace prizma::render
