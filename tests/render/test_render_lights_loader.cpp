// Scene files with point, sphere, spot and environment-map lights: the fields as loaded, the
// image read through OpenImageIO, and one error per bad field (the house one-line message).
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <nlohmann/json.hpp>

#include "prizma/render/scene.h"
#include "prizma/spectral/error.h"
#include "test_scene_util.h"

namespace prizma::render {
namespace {

using nlohmann::json;
using testing::ScratchDir;

json scene_with(const json& light) {
  json s = json::parse(R"({
    "volume": {"type": "procedural", "name": "cube_sphere", "resolution": 8},
    "materials": [{"name": "m", "range": [1, 255], "albedo": 0.5, "extinction": 2}],
    "camera": {"width": 4, "height": 4},
    "bins": "linear:400:700:4", "samples": 1
  })");
  s["lights"] = json::array({light});
  return s;
}

// A float RGB EXR of w × h pixels, pixel (x, y) = (r, g, b)(x, y).
void write_exr(const std::filesystem::path& path, int w, int h, const std::vector<float>& rgb) {
  auto out = OIIO::ImageOutput::create(path.string());
  ASSERT_TRUE(out);
  ASSERT_TRUE(out->open(path.string(), OIIO::ImageSpec(w, h, 3, OIIO::TypeDesc::FLOAT)));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, rgb.data()));
  ASSERT_TRUE(out->close());
}

std::string load_error(const ScratchDir& dir, const json& light) {
  const auto path = dir.write("s.json", scene_with(light).dump());
  try {
    load_scene(path);
  } catch (const spectral::InputError& e) {
    const std::string what = e.what();
    const std::string prefix = path.string() + ": ";
    return what.rfind(prefix, 0) == 0 ? what.substr(prefix.size()) : what;
  }
  return "no error";
}

TEST(LightLoader, PointSphereAndSpotLights) {
  const ScratchDir dir;
  const auto p = dir.write("s.json", scene_with({{"name", "bulb"}, {"position", {0.5, 2, -1}}, {"radius", 0.1}}).dump());
  const Scene s = load_scene(p);
  ASSERT_EQ(s.lights.size(), 1u);
  EXPECT_TRUE(s.lights[0].is_point);
  EXPECT_EQ(s.lights[0].position, Eigen::Vector3d(0.5, 2, -1));
  EXPECT_EQ(s.lights[0].radius, 0.1);
  EXPECT_EQ(s.lights[0].spot_direction.squaredNorm(), 0.0);

  const auto q = dir.write(
      "t.json",
      scene_with({{"name", "spot"}, {"position", {0, 0, 3}}, {"spot", {{"direction", {0, 0, -2}}, {"cone_deg", 25}, {"falloff_deg", 5}}}}).dump());
  const Scene t = load_scene(q);
  EXPECT_TRUE(t.lights[0].is_point);
  EXPECT_EQ(t.lights[0].spot_direction, Eigen::Vector3d(0, 0, -1));
  EXPECT_EQ(t.lights[0].spot_cone_deg, 25.0);
  EXPECT_EQ(t.lights[0].spot_falloff_deg, 5.0);
}

TEST(LightLoader, EnvironmentMapFromAnExr) {
  // RGB pixels become Rec. 709 luminance; the image's pixels enter the scene hash.
  const ScratchDir dir;
  write_exr(dir / "sky.exr", 2, 1, {1, 0, 0, 0, 0.5f, 2});
  const auto p = dir.write("s.json", scene_with({{"name", "sky"}, {"environment", "sky.exr"}, {"rotation_deg", 45}}).dump());
  const Scene s = load_scene(p);
  ASSERT_TRUE(s.lights[0].environment_map);
  const EnvironmentMap& m = *s.lights[0].environment_map;
  EXPECT_EQ(m.width(), 2);
  EXPECT_EQ(m.height(), 1);
  EXPECT_NEAR(m.values()[0], 0.2126, 1e-6);
  EXPECT_NEAR(m.values()[1], 0.7152 * 0.5 + 0.0722 * 2, 1e-6);
  EXPECT_EQ(s.lights[0].rotation_deg, 45.0);
  EXPECT_EQ(s.lights[0].environment_file, "sky.exr");
  write_exr(dir / "sky.exr", 2, 1, {1, 0, 0, 0, 0.5f, 3});
  EXPECT_NE(load_scene(p).hash, s.hash);
}

TEST(LightLoader, BadFieldsNameTheField) {
  const ScratchDir dir;
  write_exr(dir / "neg.exr", 2, 1, {1, 1, 1, -1, 0, 0});
  write_exr(dir / "nan.exr", 2, 1, {1, 1, 1, 0, std::nanf(""), 0});
  write_exr(dir / "black.exr", 2, 1, {0, 0, 0, 0, 0, 0});
  dir.write("text.exr", "not an image\n");
  const json bulb = {{"name", "b"}, {"position", {0, 0, 2}}};
  auto with = [&](json base, const char* key, const json& value) {
    base[key] = value;
    return base;
  };
  EXPECT_EQ(load_error(dir, with(bulb, "radius", -1)), "lights[0].radius: must be in [0, 1000000] (got -1)");
  EXPECT_EQ(load_error(dir, with(bulb, "radius", "big")), "lights[0].radius: must be a number (got string \"big\")");
  EXPECT_EQ(load_error(dir, with(bulb, "position", {0, 1})), "lights[0].position: must be an array of 3 numbers (got array [0,1])");
  EXPECT_EQ(load_error(dir, with(bulb, "position", {0, 1, 1e7})), "lights[0].position[2]: must be in [-1000000, 1000000] (got 10000000)");
  EXPECT_EQ(load_error(dir, with(bulb, "direction", {0, 0, 1})),
            "lights[0].direction: does not apply to a light with position (a light has one of direction, position and environment)");
  EXPECT_EQ(load_error(dir, with(bulb, "rotation_deg", 3)),
            "lights[0].rotation_deg: applies to environment-map lights only (this light has a position)");
  EXPECT_EQ(load_error(dir, with(bulb, "spot", {{"direction", {0, 0, -1}}})), "lights[0].spot.cone_deg: is required (half-angle of the cone, degrees)");
  EXPECT_EQ(load_error(dir, with(bulb, "spot", {{"direction", {0, 0, 0}}, {"cone_deg", 10}})), "lights[0].spot.direction: must not be [0, 0, 0]");
  EXPECT_EQ(load_error(dir, with(bulb, "spot", {{"direction", {0, 0, -1}}, {"cone_deg", 0}})), "lights[0].spot.cone_deg: must be in (0, 180] (got 0)");
  EXPECT_EQ(load_error(dir, with(bulb, "spot", {{"direction", {0, 0, -1}}, {"cone_deg", 10}, {"falloff_deg", 11}})),
            "lights[0].spot.falloff_deg: must be in [0, cone_deg] = [0, 10] (got 11)");
  EXPECT_EQ(load_error(dir, with(bulb, "spot", {{"direction", {0, 0, -1}}, {"cone_deg", 10}, {"width", 1}})),
            "lights[0].spot.width: unknown field (known: direction, cone_deg, falloff_deg)");
  EXPECT_EQ(load_error(dir, with(with(bulb, "radius", 0.1), "spot", {{"direction", {0, 0, -1}}, {"cone_deg", 10}})),
            "lights[0].spot: a spot light is a point: give radius 0 or no spot");
  EXPECT_EQ(load_error(dir, {{"name", "s"}, {"direction", {0, 0, 1}}, {"radius", 1}}),
            "lights[0].radius: applies to point lights only (give position, not direction)");

  const json sky = {{"name", "s"}, {"environment", "neg.exr"}};
  EXPECT_EQ(load_error(dir, sky).find("lights[0].environment: image "), 0u) << load_error(dir, sky);
  EXPECT_NE(load_error(dir, sky).find("pixel (1, 0) channel R = -1 (must be finite and ≥ 0)"), std::string::npos);
  EXPECT_NE(load_error(dir, with(sky, "environment", "nan.exr")).find("pixel (1, 0) channel G = nan"), std::string::npos);
  EXPECT_NE(load_error(dir, with(sky, "environment", "black.exr")).find("every pixel is 0"), std::string::npos);
  EXPECT_NE(load_error(dir, with(sky, "environment", "text.exr")).find("lights[0].environment: cannot read image"), std::string::npos);
  EXPECT_NE(load_error(dir, with(sky, "environment", "missing.exr")).find("lights[0].environment: image"), std::string::npos);
  EXPECT_EQ(load_error(dir, with(sky, "environment", 3)), "lights[0].environment: must be a string (got number 3)");
  EXPECT_EQ(load_error(dir, with(sky, "rotation_deg", 400)), "lights[0].rotation_deg: must be in [-360, 360] (got 400)");
  EXPECT_EQ(load_error(dir, with(sky, "radius", 1)), "lights[0].radius: applies to point lights only (this light is an environment map)");
}

}  // namespace
}  // namespace prizma::render
