// load_scene's camera, lights and settings sections (renderer/src/scene/scene_camera.cpp,
// scene_lights.cpp, scene_settings.cpp): their errors, and directions that stay directions.
#include "scene_loader_test_support.h"

namespace prizma::render {
namespace {

using namespace scene_test;

TEST(SceneLoaderErrors, Lights) {
  ScratchDir dir;
  expect_errors(dir, {
      {"lights[1].name", "duplicate light name", [](json& j) { j["lights"][1]["name"] = "side"; }},
      {"lights[0].name", "letters, digits", [](json& j) { j["lights"][0]["name"] = "key light"; }},
      {"lights[0].name", "1 to 64", [](json& j) { j["lights"][0]["name"] = ""; }},
      {"lights", "at least one light", [](json& j) { j["lights"] = json::array(); }},
      {"lights", "is required", [](json& j) { j.erase("lights"); }},
      {"lights[0].angular_size_deg", "[0, 180)", [](json& j) { j["lights"][0]["angular_size_deg"] = 180; }},
      {"lights[0].direction", "is required", [](json& j) { j["lights"][0].erase("direction"); }},
  });
}

TEST(SceneLoaderErrors, CameraAndSettings) {
  ScratchDir dir;
  expect_errors(dir, {
      {"camera.width", "must be in [1, 16384] (got 0)", [](json& j) { j["camera"]["width"] = 0; }},
      {"camera.fov_deg", "(0, 180)", [](json& j) { j["camera"]["fov_deg"] = 180; }},
      {"camera.look_at", "must differ from position", [](json& j) { j["camera"]["look_at"] = {0, 0, 3}; }},
      {"camera.up", "parallel", [](json& j) { j["camera"]["up"] = {0, 0, -1}; }},
      // its square overflows: once "up parallel", misleading
      {"camera.position[0]", "must be within ±1e12 (got 1e+200)",
       [](json& j) { j["camera"]["position"] = {1e200, 0.5, 0.5}; }},
      {"camera.look_at[1]", "must be within ±1e12", [](json& j) { j["camera"]["look_at"] = {0, -1e13, 0}; }},
      {"camera.type", "perspective", [](json& j) { j["camera"]["type"] = "fisheye"; }},
      {"samples", "must be in [1,", [](json& j) { j["samples"] = 0; }},
      {"seed", "≥ 0", [](json& j) { j["seed"] = -1; }},
      {"max_bounces", "[-1,", [](json& j) { j["max_bounces"] = -2; }},
      {"wavelength_sampling", "spectral-tracking", [](json& j) { j["wavelength_sampling"] = "hero"; }},
      {"sampler", "known: independent, sobol", [](json& j) { j["sampler"] = "halton"; }},
      {"event_probabilities", "\"max\", \"average\"", [](json& j) { j["event_probabilities"] = "maximum"; }},
      {"mis_lane_groups", "must be \"auto\" or an integer ≥ 1 (got string \"four\")", [](json& j) { j["mis_lane_groups"] = "four"; }},
      {"mis_lane_groups", "must be in [1, 1024] (got 0)", [](json& j) { j["mis_lane_groups"] = 0; }},
      {"output", "must not be empty", [](json& j) { j["output"] = ""; }},
  });
  json j = base_scene();
  j["bins"] = "linear:700:400:12";
  const auto path = write_scene(dir, j);
  try {
    load_scene(path);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path.string() + ": bins"), std::string::npos) << e.what();
  }
}

// issue 11: a light direction of length 1e-200 (norm underflows) or 1e200 (overflows) became the
// environment light; only the zero vector is the environment.
TEST(SceneLoader, TinyAndHugeLightDirectionsStayDirections) {
  ScratchDir dir;
  json j = base_scene();
  j["lights"][0]["direction"] = {1e-200, 0, 0};
  j["lights"][1]["direction"] = {0, -1e200, 1e200};
  const Scene s = load_scene(write_scene(dir, j));
  EXPECT_TRUE(s.lights[0].direction.isApprox(Eigen::Vector3d(1, 0, 0))) << s.lights[0].direction.transpose();
  EXPECT_TRUE(s.lights[1].direction.isApprox(Eigen::Vector3d(0, -1, 1).normalized()))
      << s.lights[1].direction.transpose();
}

// issue 21: every direction of a scene goes through one normalisation (scaled by its largest
// component first): a spot's axis or the camera's up of norm 1e-300 or 1e300 keeps its direction
// (the camera's up of 1e-300 was refused as the zero vector, its
// coordinates stay within ±1e12); [0, 0, 0] is still refused.
TEST(SceneLoader, TinyAndHugeSpotAxesAndCameraUpKeepTheirDirection) {
  ScratchDir dir;
  json j = base_scene();
  j["camera"]["up"] = {0, 1e-300, 0};
  j["lights"][0] = {{"name", "spot"}, {"position", {0, 0, 2}},
                    {"spot", {{"direction", {0, 0, -1e300}}, {"cone_deg", 10}}}};
  const Scene s = load_scene(write_scene(dir, j));
  EXPECT_EQ(s.camera.up, Eigen::Vector3d(0, 1, 0));
  EXPECT_EQ(s.lights[0].spot_direction, Eigen::Vector3d(0, 0, -1));
  j["camera"]["up"] = {1e-200, 0, 1e-200};
  EXPECT_TRUE(load_scene(write_scene(dir, j)).camera.up.isApprox(Eigen::Vector3d(1, 0, 1).normalized()));
  j["camera"]["up"] = {0, 0, 0};
  expect_error(dir, j, "camera.up", "must not be the zero vector");
}

}  // namespace
}  // namespace prizma::render
