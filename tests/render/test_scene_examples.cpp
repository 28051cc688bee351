// Every example scene in data/scenes/ loads, has lights and a medium with something in it, and
// keeps modest defaults (they are rendered by the demos and the end-to-end tests).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <fstream>

#include "prizma/render/scene.h"

namespace prizma::render {
namespace {

std::vector<std::filesystem::path> example_scenes() {
  std::vector<std::filesystem::path> out;
  for (const auto& e : std::filesystem::directory_iterator(std::filesystem::path(PRIZMA_TEST_DATA_DIR) / "scenes")) {
    if (e.path().extension() == ".json") out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

bool needs_missing_file(const std::filesystem::path& scene) {
  std::ifstream in(scene);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string kMricron = "/usr/share/mricron/";
  return text.find(kMricron) != std::string::npos && !std::filesystem::exists(kMricron);
}

TEST(ExampleScenes, AllLoad) {
  const auto scenes = example_scenes();
  ASSERT_GE(scenes.size(), 3u);
  for (const auto& path : scenes) {
    SCOPED_TRACE(path.string());
    if (needs_missing_file(path)) {
      std::cout << "skipping " << path << ": mricron-data is not installed\n";
      continue;
    }
    const Scene s = load_scene(path);
    EXPECT_FALSE(s.lights.empty());
    EXPECT_FALSE(s.medium.materials.empty());
    EXPECT_GT(s.medium.voxel_count(), 0u);
    const auto filled = std::count_if(s.medium.material.begin(), s.medium.material.end(),
                                      [](std::uint16_t m) { return m != Medium::kEmpty; });
    EXPECT_GT(filled, 0);
    // Every material is used by some voxel.
    std::vector<bool> used(s.medium.materials.size(), false);
    for (std::uint16_t m : s.medium.material) {
      if (m != Medium::kEmpty) used[m] = true;
    }
    for (std::size_t i = 0; i < used.size(); ++i) EXPECT_TRUE(used[i]) << s.medium.materials[i].name;
    EXPECT_LE(s.camera.width * s.camera.height, 512 * 512);
    EXPECT_LE(s.settings.sample_end, 256);
    EXPECT_EQ(s.hash.size(), 16u);
  }
}

TEST(ExampleScenes, CubeSphereIsBlueThickRedThin) {
  // The Rayleigh cube: optical thickness across the cube (0.8 scene units) 1–3 at 450 nm and well
  // below 1 at 650 nm, so side light scatters blue and back light transmits red.
  const Scene s = load_scene(std::filesystem::path(PRIZMA_TEST_DATA_DIR) / "scenes/cube_sphere.json");
  const auto& cube = *std::find_if(s.medium.materials.begin(), s.medium.materials.end(),
                                   [](const Material& m) { return m.name == "rayleigh"; });
  const double tau450 = cube.sigma_t_per_unit.eval(450.0) * 0.8;
  const double tau650 = cube.sigma_t_per_unit.eval(650.0) * 0.8;
  EXPECT_GT(tau450, 1.0);
  EXPECT_LT(tau450, 3.0);
  EXPECT_LT(tau650, 0.7);
  EXPECT_NEAR(tau650 / tau450, std::pow(450.0 / 650.0, 4.0), 1e-3);  // λ^-4
  std::vector<std::string> names;
  for (const auto& l : s.lights) names.push_back(l.name);
  EXPECT_NE(std::find(names.begin(), names.end(), "side"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "back"), names.end());
}

}  // namespace
}  // namespace prizma::render
