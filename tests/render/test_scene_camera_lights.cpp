// load_scene's camera, lights and settings sections (renderer/src/scene/scene_camera.cpp,
// scene_lights.cpp, scene_settings.cpp): their errors, and directions that stay directions.
#include "scene_loader_test_support.h"

namespace prizma::render {
namespace {

using namespace scene_test;

TEST(SceneLoaderErrors, Lights) {
  ScratchDir dir;
  json j = base_scene();
  j["lights"][1]["name"] = "side";
  expect_error(dir, j, "lights[1].name", "duplicate light name");
  j = base_scene();
  j["lights"][0]["name"] = "key light";
  expect_error(dir, j, "lights[0].name", "letters, digits");
  j = base_scene();
  j["lights"][0]["name"] = "";
  expect_error(dir, j, "lights[0].name", "1 to 64");
  j = base_scene();
  j["lights"] = json::array();
  expect_error(dir, j, "lights", "at least one light");
  j = base_scene();
  j.erase("lights");
  expect_error(dir, j, "lights", "is required");
  j = base_scene();
  j["lights"][0]["angular_size_deg"] = 180;
  expect_error(dir, j, "lights[0].angular_size_deg", "[0, 180)");
  j = base_scene();
  j["lights"][0].erase("direction");
  expect_error(dir, j, "lights[0].direction", "is required");
}

TEST(SceneLoaderErrors, CameraAndSettings) {
  ScratchDir dir;
  json j = base_scene();
  j["camera"]["width"] = 0;
  expect_error(dir, j, "camera.width", "must be in [1, 16384] (got 0)");
  j = base_scene();
  j["camera"]["fov_deg"] = 180;
  expect_error(dir, j, "camera.fov_deg", "(0, 180)");
  j = base_scene();
  j["camera"]["look_at"] = {0, 0, 3};
  expect_error(dir, j, "camera.look_at", "must differ from position");
  j = base_scene();
  j["camera"]["up"] = {0, 0, -1};
  expect_error(dir, j, "camera.up", "parallel");
  j = base_scene();
  j["camera"]["position"] = {1e200, 0.5, 0.5};  // its square overflows: once "up parallel", misleading
  expect_error(dir, j, "camera.position[0]", "must be within ±1e12 (got 1e+200)");
  j = base_scene();
  j["camera"]["look_at"] = {0, -1e13, 0};
  expect_error(dir, j, "camera.look_at[1]", "must be within ±1e12");
  j = base_scene();
  j["camera"]["type"] = "fisheye";
  expect_error(dir, j, "camera.type", "perspective");
  j = base_scene();
  j["samples"] = 0;
  expect_error(dir, j, "samples", "must be in [1,");
  j = base_scene();
  j["seed"] = -1;
  expect_error(dir, j, "seed", "≥ 0");
  j = base_scene();
  j["max_bounces"] = -2;
  expect_error(dir, j, "max_bounces", "[-1,");
  j = base_scene();
  j["wavelength_sampling"] = "hero";
  expect_error(dir, j, "wavelength_sampling", "spectral-tracking");
  j = base_scene();
  j["sampler"] = "halton";
  expect_error(dir, j, "sampler", "known: independent, sobol");
  j = base_scene();
  j["event_probabilities"] = "maximum";
  expect_error(dir, j, "event_probabilities", "\"max\", \"average\"");
  j = base_scene();
  j["output"] = "";
  expect_error(dir, j, "output", "must not be empty");
  j = base_scene();
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
