// Environment-map conventions (issue 25 item 15): one bright texel lands in the direction each
// convention's closed form gives (Prizma's latitude–longitude map, Mitsuba 3's, pbrt-v4's
// equal-area square), the densities integrate to one and match the samples, and the scene file
// refuses a square map that does not say which it is.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <numbers>
#include <nlohmann/json.hpp>
#include <vector>

#include "environment_test_util.h"
#include "prizma/render/environment_map.h"
#include "prizma/render/rng.h"
#include "prizma/render/scene.h"
#include "prizma/spectral/error.h"
#include "test_scene_util.h"

namespace prizma::render {
namespace {


// A w × h map of `dim` everywhere but texel (x, y) = `bright`.
EnvironmentMap one_texel(int w, int h, int x, int y, EnvironmentConvention c, double rotation_deg = 0.0,
                         float dim = 0.0f, float bright = 1.0f) {
  std::vector<float> v(static_cast<std::size_t>(w) * h, dim);
  v[static_cast<std::size_t>(y) * w + x] = bright;
  return EnvironmentMap(w, h, std::move(v), rotation_deg, "test", c);
}

Eigen::Vector3d unit(double x, double y, double z) { return Eigen::Vector3d(x, y, z).normalized(); }

// The mean direction sample() draws from a map whose only light is one texel, and the largest
// angle (degrees) of a draw from it.
Eigen::Vector3d mean_draw(const EnvironmentMap& m, double& spread_deg) {
  Rng rng(9, 0, 0);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> draws;
  for (int k = 0; k < 2000; ++k) {
    Eigen::Vector3d d;
    double radiance = 0.0;
    EXPECT_GT(m.sample(rng.uniform_double(), rng.uniform_double(), d, radiance), 0.0);
    EXPECT_EQ(radiance, 1.0);
    sum += d;
    draws.push_back(d);
  }
  const Eigen::Vector3d mean = sum.normalized();
  spread_deg = 0.0;
  for (const auto& d : draws) spread_deg = std::max(spread_deg, std::acos(std::clamp(d.dot(mean), -1.0, 1.0)) * 180.0 / std::numbers::pi);
  return mean;
}

TEST(EnvironmentConventions, PrizmaAndMitsubaLatLongTexelsLandWhereTheirFormulasSay) {
  // 8 × 4 texels; texel (6, 1) spans u ∈ [¾, ⅞), v ∈ [¼, ½): Prizma's φ = 2π(u − ½) ∈ [π/2, 3π/4),
  // θ ∈ [π/4, π/2): around +x, tilted toward +z and up. Mitsuba's φ = 2πu puts the same texel
  // 180° about +y from it: around −x, tilted toward −z.
  const double theta = 3.0 * std::numbers::pi / 8.0, phi = 5.0 * std::numbers::pi / 8.0;  // the texel's centre
  const Eigen::Vector3d prizma_centre(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
  const Eigen::Vector3d mitsuba_centre(-prizma_centre.x(), prizma_centre.y(), -prizma_centre.z());
  const EnvironmentMap p = one_texel(8, 4, 6, 1, EnvironmentConvention::Prizma);
  const EnvironmentMap m = one_texel(8, 4, 6, 1, EnvironmentConvention::Mitsuba);
  EXPECT_EQ(p.radiance(prizma_centre), 1.0);
  EXPECT_EQ(p.radiance(mitsuba_centre), 0.0);
  EXPECT_EQ(m.radiance(mitsuba_centre), 1.0);
  EXPECT_EQ(m.radiance(prizma_centre), 0.0);
  // Mitsuba 3's envmap: u = atan2(x, −z) / 2π mod 1, v = acos(y) / π (emitters/envmap.cpp).
  const Eigen::Vector3d d = unit(0.3, -0.4, 0.8);
  double u = std::atan2(d.x(), -d.z()) / (2.0 * std::numbers::pi);
  u -= std::floor(u);
  const int col = static_cast<int>(u * 8), row = static_cast<int>(std::acos(d.y()) / std::numbers::pi * 4);
  EXPECT_EQ(one_texel(8, 4, col, row, EnvironmentConvention::Mitsuba).radiance(d), 1.0) << col << " " << row;
  // Every direction: Mitsuba's map is Prizma's turned 180° about +y.
  std::vector<float> v(32);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<float>(i + 1);
  const EnvironmentMap mp(8, 4, v, 0.0, "test", EnvironmentConvention::Mitsuba);
  const EnvironmentMap pp(8, 4, v, 180.0, "test", EnvironmentConvention::Prizma);
  Rng rng(3, 0, 0);
  for (int k = 0; k < 1000; ++k) {
    const Eigen::Vector3d dir = unit(rng.uniform_double() - 0.5, rng.uniform_double() - 0.5, rng.uniform_double() - 0.5);
    EXPECT_EQ(mp.radiance(dir), pp.radiance(dir)) << dir.transpose();
  }
  double spread = 0.0;
  EXPECT_GT(mean_draw(m, spread).dot(mitsuba_centre), std::cos(25.0 * std::numbers::pi / 180.0));
  EXPECT_LT(spread, 35.0);
}

TEST(EnvironmentConventions, PbrtEqualAreaTexelsLandWhereTheOctahedralMapSays) {
  // pbrt-v4's EqualAreaSphereToSquare of the direction (x, −z, y): the square's centre is +y (up),
  // its corners −y, the middle of its right edge +x, of its left edge −x, of its top edge +z, of
  // its bottom edge −z (row 0 is the top row).
  const int n = 9;
  EXPECT_EQ(one_texel(n, n, 4, 4, EnvironmentConvention::PbrtEqualArea).radiance({0, 1, 0}), 1.0);
  EXPECT_EQ(one_texel(n, n, 8, 4, EnvironmentConvention::PbrtEqualArea).radiance(unit(1, 0.01, 0)), 1.0);
  EXPECT_EQ(one_texel(n, n, 0, 4, EnvironmentConvention::PbrtEqualArea).radiance(unit(-1, 0.01, 0)), 1.0);
  EXPECT_EQ(one_texel(n, n, 4, 8, EnvironmentConvention::PbrtEqualArea).radiance(unit(0, 0.01, -1)), 1.0);
  EXPECT_EQ(one_texel(n, n, 4, 0, EnvironmentConvention::PbrtEqualArea).radiance(unit(0, 0.01, 1)), 1.0);
  std::vector<float> corners(static_cast<std::size_t>(n) * n, 0.0f);
  for (std::size_t i : {std::size_t{0}, std::size_t{n - 1}, std::size_t{n * (n - 1)}, std::size_t{n * n - 1}}) corners[i] = 1.0f;
  const EnvironmentMap nadir(n, n, corners, 0.0, "test", EnvironmentConvention::PbrtEqualArea);
  EXPECT_EQ(nadir.radiance({0, -1, 0}), 1.0);
  EXPECT_EQ(nadir.radiance(unit(0.01, -1, 0.02)), 1.0);
  EXPECT_EQ(nadir.radiance(unit(1, -0.3, 0.5)), 0.0);
  // Halfway down from the zenith toward +x: z = 1 − r² = cos 45° in pbrt's light space, r = 0.541,
  // on the u axis: u = ½ (r + 1) = 0.7706 → column 6 of 9.
  EXPECT_EQ(one_texel(n, n, 6, 4, EnvironmentConvention::PbrtEqualArea).radiance(unit(1, 1, 0)), 1.0);
  // The rotation turns it about +y as for every map: +90° brings +x's texel to −z.
  EXPECT_EQ(one_texel(n, n, 8, 4, EnvironmentConvention::PbrtEqualArea, 90.0).radiance(unit(0, 0.01, -1)), 1.0);

  double spread = 0.0;
  const EnvironmentMap zenith = one_texel(n, n, 4, 4, EnvironmentConvention::PbrtEqualArea);
  EXPECT_GT(mean_draw(zenith, spread).y(), 0.999);
  // The centre texel covers 4π/81 sr, a cap of angular radius ≈ 25° (it is a square on the map).
  EXPECT_LT(spread, 32.0);
}

TEST(EnvironmentConventions, EqualAreaDensityIntegratesToOneAndEveryTexelHasTheSameSolidAngle) {
  // Equal area: a texel's density is L / (mean L · 4π), so a map of one texel has 1 / (4π / n²)
  // per steradian inside it; the density integrates to 1 over the sphere (midpoint rule), and each
  // draw's L / pdf is ∫ L dω = 4π · mean L.
  const int n = 16;
  const EnvironmentMap one = one_texel(n, n, 3, 11, EnvironmentConvention::PbrtEqualArea);
  Rng rng(11, 0, 0);
  for (int k = 0; k < 100; ++k) {
    Eigen::Vector3d d;
    double radiance = 0.0;
    const double pdf = one.sample(rng.uniform_double(), rng.uniform_double(), d, radiance);
    EXPECT_NEAR(pdf, n * n / (4.0 * std::numbers::pi), 1e-9);
    EXPECT_NEAR(one.pdf(d), pdf, 1e-9);
  }
  std::vector<float> v(static_cast<std::size_t>(n) * n);
  std::uint32_t state = 777u;
  double mean_l = 0.0;
  for (float& x : v) {
    state = state * 1664525u + 1013904223u;
    x = static_cast<float>((state >> 8) % 1000) / 100.0f;
    mean_l += x;
  }
  mean_l /= static_cast<double>(v.size());
  const EnvironmentMap map(n, n, v, 21.0, "test", EnvironmentConvention::PbrtEqualArea);
  EXPECT_NEAR(testing::pdf_integral_over_sphere(map), 1.0, 2e-3);
  // Sampling is exactly proportional to radiance × solid angle: every draw's L / pdf is ∫ L dω.
  for (int k = 0; k < 10000; ++k) {
    Eigen::Vector3d d;
    double radiance = 0.0;
    const double pdf = map.sample(rng.uniform_double(), rng.uniform_double(), d, radiance);
    ASSERT_GT(pdf, 0.0);
    if (k < 1000) {
      EXPECT_NEAR(map.pdf(d), pdf, 1e-9 * pdf);
      EXPECT_EQ(map.radiance(d), radiance);
    }
    if (radiance > 0.0) {
      EXPECT_NEAR(radiance / pdf, 4.0 * std::numbers::pi * mean_l, 1e-9 * mean_l);
    }
  }
}

// A float RGB EXR of w × h grey pixels of value 1 but pixel (0, 0) = 5.
void write_grey_exr(const std::filesystem::path& path, int w, int h) {
  std::vector<float> rgb(static_cast<std::size_t>(3) * w * h, 1.0f);
  rgb[0] = rgb[1] = rgb[2] = 5.0f;
  auto out = OIIO::ImageOutput::create(path.string());
  ASSERT_TRUE(out);
  ASSERT_TRUE(out->open(path.string(), OIIO::ImageSpec(w, h, 3, OIIO::TypeDesc::FLOAT)));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, rgb.data()));
  ASSERT_TRUE(out->close());
}

std::string scene_text(const nlohmann::json& light) {
  nlohmann::json s = nlohmann::json::parse(R"({
    "volume": {"type": "procedural", "name": "cube_sphere", "resolution": 8},
    "materials": [{"name": "m", "range": [1, 255], "albedo": 0.5, "extinction": 2}],
    "camera": {"width": 4, "height": 4}, "bins": "linear:400:700:4", "samples": 1})");
  s["lights"] = nlohmann::json::array({light});
  return s.dump();
}

std::string load_error(const testing::ScratchDir& dir, const nlohmann::json& light) {
  const auto path = dir.write("s.json", scene_text(light));
  try {
    load_scene(path);
  } catch (const spectral::InputError& e) {
    return std::string(e.what()).substr(path.string().size() + 2);
  }
  return "no error";
}

TEST(EnvironmentConventions, TheSceneFileSaysTheConventionAndASquareMapMustSayIt) {
  const testing::ScratchDir dir;
  write_grey_exr(dir / "square.exr", 8, 8);
  write_grey_exr(dir / "wide.exr", 8, 4);
  EXPECT_EQ(load_error(dir, {{"name", "sky"}, {"environment", "square.exr"}}),
            "lights[0].convention: is required for the square image square.exr (8×8): \"pbrt-equal-area\" for "
            "pbrt-v4's equal-area map, or \"prizma\" or \"mitsuba\" for a latitude–longitude map");
  EXPECT_EQ(load_error(dir, {{"name", "sky"}, {"environment", "wide.exr"}, {"convention", "pbrt-equal-area"}}),
            "lights[0].environment: image " + (dir / "wide.exr").string() + ": a pbrt-equal-area map is square (got 8×4)");
  EXPECT_EQ(load_error(dir, {{"name", "sky"}, {"environment", "wide.exr"}, {"convention", "pbrt"}}),
            "lights[0].convention: unknown convention \"pbrt\" (known: prizma, mitsuba, pbrt-equal-area)");
  EXPECT_EQ(load_error(dir, {{"name", "sun"}, {"direction", {0, 1, 0}}, {"convention", "mitsuba"}}),
            "lights[0].convention: applies to environment-map lights only (give environment, not direction)");
  for (const char* c : {"prizma", "mitsuba", "pbrt-equal-area"}) {
    const auto path = dir.write("s.json", scene_text({{"name", "sky"}, {"environment", "square.exr"}, {"convention", c}}));
    const Scene s = load_scene(path);
    ASSERT_TRUE(s.lights[0].environment_map);
    EXPECT_STREQ(environment_convention_name(s.lights[0].environment_map->convention()), c);
  }
  // A wide map is Prizma's unless it says otherwise.
  const Scene wide = load_scene(dir.write("s.json", scene_text({{"name", "sky"}, {"environment", "wide.exr"}})));
  EXPECT_EQ(wide.lights[0].environment_map->convention(), EnvironmentConvention::Prizma);
}

}  // namespace
}  // namespace prizma::render
