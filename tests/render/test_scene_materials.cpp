// load_scene's materials section (renderer/src/scene/scene_materials.cpp): ranges, albedo,
// extinction, anisotropy and their spectra, and what the tracker cannot represent.
#include "scene_loader_test_support.h"

namespace prizma::render {
namespace {

using namespace scene_test;

TEST(SceneLoader, NormalisedRangesAndOrthographicCamera) {
  ScratchDir dir;
  json j = base_scene();
  j["normalisation"] = {{"min", 0}, {"max", 255}};
  j["materials"][1]["units"] = "normalised";
  j["materials"][1]["range"] = {0.7, 1.0};                 // raw ≥ 178.5: the sphere
  j["materials"][1]["density"] = {{0.0, 2.0}, {1.0, 2.0}};  // constant 2
  j["camera"] = {{"type", "orthographic"}, {"ortho_height", 2.5}, {"width", 8}, {"height", 8}};
  const Scene s = load_scene(write_scene(dir, j));
  auto idx = [](int x, int y, int z) { return (static_cast<std::size_t>(z) * 16 + y) * 16 + x; };
  EXPECT_EQ(s.medium.material[idx(8, 8, 8)], 1);
  EXPECT_FLOAT_EQ(s.medium.density[idx(8, 8, 8)], 2.0f);
  EXPECT_EQ(s.camera.type, CameraType::Orthographic);
  EXPECT_DOUBLE_EQ(s.camera.ortho_height, 2.5);
}

TEST(SceneLoaderErrors, OutOfRangeMaterialValues) {
  ScratchDir dir;
  expect_errors(dir, {
      {"materials[0].extinction.scale", "must be > 0 (got -3)",
       [](json& j) { j["materials"][0]["extinction"]["scale"] = -3; }},
      {"materials[1].albedo", "[0, 1]", [](json& j) { j["materials"][1]["albedo"] = 1.5; }},
      // patch 19 (white) ≈ 0.9 → 2.7
      {"materials[1].albedo", "[0, 1]",
       [](json& j) { j["materials"][1]["albedo"] = {{"spectrum", "cc:19"}, {"scale", 3}}; }},
      {"materials[0].extinction", "≥ 0", [](json& j) { j["materials"][0]["extinction"] = -1; }},
      {"materials[0].anisotropy", "(-1, 1)", [](json& j) { j["materials"][0]["anisotropy"] = 1.0; }},
      {"materials[0].range", "lo must be ≤ hi", [](json& j) { j["materials"][0]["range"] = {150, 50}; }},
      {"materials[1].density[1][0]", "strictly increasing",
       [](json& j) { j["materials"][1]["density"] = {{200, 1}, {100, 2}}; }},
      {"materials[1].density[0][1]", "≥ 0", [](json& j) { j["materials"][1]["density"] = {{200, -1}}; }},
      {"materials[1].name", "duplicate material name", [](json& j) { j["materials"][1]["name"] = "cube"; }},
      {"materials", "at least one", [](json& j) { j["materials"] = json::array(); }},
  });
}

// Anisotropy is signed, so a csv: table of g may hold negative values (backward scattering); the
// other material spectra may not (issue 27).
TEST(SceneLoader, AnisotropyTableMayBeNegativeOtherSpectraMayNot) {
  ScratchDir dir;
  const auto table = dir.write("g.csv", "wavelength_nm,g\n400,-0.6\n550,-0.2\n700,0.3\n");
  json j = base_scene();
  j["materials"][0]["anisotropy"] = "csv:g.csv";
  j["materials"][1]["anisotropy"] = {{"spectrum", "csv:g.csv"}, {"scale", 0.5}};
  const Scene s = load_scene(write_scene(dir, j));
  EXPECT_DOUBLE_EQ(s.medium.materials[0].anisotropy.eval(400.0), -0.6);
  EXPECT_DOUBLE_EQ(s.medium.materials[1].anisotropy.eval(400.0), -0.3);
  j["materials"][0]["anisotropy"] = "-0.4";
  EXPECT_DOUBLE_EQ(load_scene(write_scene(dir, j)).medium.materials[0].anisotropy.eval(500.0), -0.4);
  j["materials"][0]["anisotropy"] = "csv:g.csv*2";  // −1.2: signed, but outside (−1, 1)
  expect_error(dir, j, "materials[0].anisotropy", "(-1, 1)");
  for (const char* field : {"albedo", "extinction", "emission"}) {
    j = base_scene();
    j["materials"][0][field] = "csv:g.csv";
    const auto path = write_scene(dir, j);
    try {
      load_scene(path);
      ADD_FAILURE() << field << ": a negative table loaded";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()), table.string() + ":2: value must not be negative, got -0.6") << field;
    }
  }
}

TEST(SceneLoaderErrors, BadSpectrumSpecsNameTheField) {
  ScratchDir dir;
  json j = base_scene();
  j["materials"][1]["albedo"] = "cc:no-such-patch";
  const auto path = write_scene(dir, j);
  try {
    load_scene(path);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path.string() + ": materials[1].albedo"), std::string::npos) << e.what();
  }
  j = base_scene();
  j["lights"][1]["spectrum"] = "D66";
  const auto path2 = write_scene(dir, j);
  try {
    load_scene(path2);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path2.string() + ": lights[1].spectrum"), std::string::npos) << e.what();
  }
}

// issue 11: an extinction (or extinction × density) beyond what the tracker can step through
// passed validation and the render never ended.
TEST(SceneLoader, RefusesExtinctionTheTrackerCannotRepresent) {
  ScratchDir dir;
  expect_errors(dir, {
      // beyond float
      {"materials[1].extinction", "extinction × density reaches",
       [](json& j) { j["materials"][1]["extinction"] = 1e39; }},
      {"materials[1].extinction", "per unit length", [](json& j) { j["materials"][1]["extinction"] = 2e6; }},
      // 5e6 per unit
      {"materials[0].extinction", "extinction × density reaches",
       [](json& j) { j["materials"][0]["extinction"] = 1000; j["materials"][0]["density"] = 5000; }},
      {"materials[1].density[1][1]", "must be at most",
       [](json& j) { j["materials"][1]["density"] = {{200, 0.5}, {255, 1e300}}; }},
  });
  // The bound itself is fine, and an extinction outside any voxel's material costs nothing.
  json j = base_scene();
  j["materials"][1]["extinction"] = 1e6;
  EXPECT_NO_THROW(load_scene(write_scene(dir, j)));
}

}  // namespace
}  // namespace prizma::render
