// load_scene: the happy path (every field), relative paths, the hash, and one test per class of
// input error, each checking the field path ("<file>: <field path>") and the reason.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <sys/stat.h>

#include <cstring>
#include <nlohmann/json.hpp>

#include "prizma/render/scene.h"
#include "prizma/spectral/error.h"
#include "test_scene_util.h"

namespace prizma::render {
namespace {

using nlohmann::json;
using spectral::InputError;
using testing::ScratchDir;

json base_scene() {
  return json::parse(R"({
    "description": "test scene",
    "volume": {"type": "procedural", "name": "cube_sphere", "resolution": 16},
    "materials": [
      {"name": "cube", "range": [50, 150], "albedo": 0.99, "extinction": {"spectrum": "1", "scale": 3},
       "anisotropy": 0},
      {"name": "sphere", "range": [200, 255], "albedo": "cc:dark-skin", "extinction": 5,
       "density": [[200, 0.5], [255, 1]]}
    ],
    "camera": {"type": "perspective", "position": [0, 0, 3], "look_at": [0, 0, 0], "up": [0, 1, 0],
               "fov_deg": 40, "width": 32, "height": 24},
    "lights": [{"name": "side", "direction": [2, 0, 0], "spectrum": "D65", "angular_size_deg": 1},
               {"name": "sky", "direction": [0, 0, 0]}],
    "bins": "linear:400:700:12",
    "samples": 8,
    "seed": 7,
    "max_bounces": 5,
    "wavelength_sampling": "single",
    "sampler": "sobol",
    "output": "out/x.exr"
  })");
}

std::filesystem::path write_scene(const ScratchDir& dir, const json& j, const std::string& name = "scene.json") {
  return dir.write(name, j.dump(2));
}

// Loads and expects an InputError with input "<file>: <field>" and a reason containing `reason`.
void expect_error(const ScratchDir& dir, const json& j, const std::string& field, const std::string& reason) {
  const auto path = write_scene(dir, j);
  try {
    load_scene(path);
    FAIL() << "no error; expected " << field << ": " << reason;
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), path.string() + (field.empty() ? "" : ": " + field)) << e.what();
    EXPECT_NE(e.reason().find(reason), std::string::npos) << e.what();
  }
}

// The InputError that loading `path` throws; a test failure (and an empty error) when none is thrown.
InputError load_error(const std::filesystem::path& path) {
  try {
    load_scene(path);
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << path << ": no InputError";
  return InputError("", "");
}

TEST(SceneLoader, HappyPathFillsEveryField) {
  ScratchDir dir;
  const auto path = write_scene(dir, base_scene());
  const Scene s = load_scene(path);
  EXPECT_EQ(s.source, path);
  EXPECT_EQ(s.output, dir.path() / "out/x.exr");
  EXPECT_EQ(s.hash.size(), 16u);
  // Medium: 16³ cube_sphere, two materials.
  EXPECT_EQ(s.medium.dims, (std::array<int, 3>{16, 16, 16}));
  ASSERT_EQ(s.medium.materials.size(), 2u);
  EXPECT_EQ(s.medium.materials[0].name, "cube");
  EXPECT_DOUBLE_EQ(s.medium.materials[0].sigma_t_per_unit.eval(550.0), 3.0);
  EXPECT_DOUBLE_EQ(s.medium.materials[0].albedo.eval(550.0), 0.99);
  EXPECT_DOUBLE_EQ(s.medium.materials[1].sigma_t_per_unit.eval(550.0), 5.0);
  EXPECT_GT(s.medium.materials[1].albedo.eval(600.0), 0.0);
  EXPECT_LT(s.medium.materials[1].albedo.eval(600.0), 1.0);
  EXPECT_TRUE(s.medium.bounds_max.isApprox(Eigen::Vector3d(0.5, 0.5, 0.5)));
  // Voxels: centre = sphere (value 255 → density 1), corner empty, cube region = material 0.
  auto idx = [](int x, int y, int z) { return (static_cast<std::size_t>(z) * 16 + y) * 16 + x; };
  EXPECT_EQ(s.medium.material[idx(8, 8, 8)], 1);
  EXPECT_FLOAT_EQ(s.medium.density[idx(8, 8, 8)], 1.0f);
  EXPECT_EQ(s.medium.material[idx(0, 0, 0)], Medium::kEmpty);
  EXPECT_EQ(s.medium.material[idx(2, 8, 8)], 0);
  // Camera, lights, settings.
  EXPECT_EQ(s.camera.type, CameraType::Perspective);
  EXPECT_EQ(s.camera.width, 32);
  EXPECT_EQ(s.camera.height, 24);
  EXPECT_DOUBLE_EQ(s.camera.fov_y_deg, 40.0);
  EXPECT_TRUE(s.camera.position.isApprox(Eigen::Vector3d(0, 0, 3)));
  ASSERT_EQ(s.lights.size(), 2u);
  EXPECT_EQ(s.lights[0].name, "side");
  EXPECT_TRUE(s.lights[0].direction.isApprox(Eigen::Vector3d(1, 0, 0)));  // normalised
  EXPECT_DOUBLE_EQ(s.lights[0].angular_size_deg, 1.0);
  EXPECT_EQ(s.lights[1].direction, Eigen::Vector3d::Zero());
  EXPECT_EQ(s.lights[1].spectrum_spec, "D65");
  EXPECT_EQ(s.settings.bins, spectral::BinLayout::linear(400, 700, 12));
  EXPECT_EQ(s.settings.sample_begin, 0);
  EXPECT_EQ(s.settings.sample_end, 8);
  EXPECT_EQ(s.settings.seed, 7u);
  EXPECT_EQ(s.settings.max_bounces, 5);
  EXPECT_EQ(s.settings.wavelength_sampling, WavelengthSampling::Single);
  EXPECT_EQ(s.settings.sampler, Sampler::Sobol);
}

TEST(SceneLoader, DefaultsWhenOptionalFieldsAreMissing) {
  ScratchDir dir;
  json j = base_scene();
  for (const char* k : {"camera", "bins", "samples", "seed", "max_bounces", "wavelength_sampling", "sampler", "output", "description"}) {
    j.erase(k);
  }
  const Scene s = load_scene(write_scene(dir, j, "minimal.json"));
  EXPECT_EQ(s.output, dir.path() / "minimal.exr");
  EXPECT_EQ(s.camera.width, 256);
  EXPECT_EQ(s.settings.sample_end, 64);
  EXPECT_EQ(s.settings.seed, 1u);
  EXPECT_EQ(s.settings.max_bounces, -1);
  EXPECT_EQ(s.settings.wavelength_sampling, WavelengthSampling::Auto);
  EXPECT_EQ(s.settings.sampler, Sampler::Independent);
  EXPECT_EQ(s.settings.event_probabilities, EventProbabilities::Auto);
  EXPECT_EQ(s.settings.bins, spectral::BinLayout());
  // The scheme is a scene field, so -D sets it too.
  EXPECT_EQ(load_scene(dir / "minimal.json", {parse_scene_override("event_probabilities=implicit")})
                .settings.event_probabilities,
            EventProbabilities::Implicit);
}

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

TEST(SceneLoader, RawVolumeAndCsvPathsAreRelativeToTheSceneFile) {
  ScratchDir dir;
  std::filesystem::create_directories(dir / "sub/data");
  // 2×2×2 uint16 big-endian: values 0..7 (value 7 at the last voxel).
  std::string bytes;
  for (int i = 0; i < 8; ++i) bytes += {static_cast<char>(0), static_cast<char>(i)};
  dir.write("sub/data/v_2x2x2_uint16.raw", bytes);
  dir.write("sub/data/ext.csv", "nm,value\n400,1\n700,2\n");
  json j = base_scene();
  j["volume"] = {{"type", "raw"}, {"path", "data/v_2x2x2_uint16.raw"}, {"endianness", "big"}, {"spacing", {1, 1, 2}}};
  j["materials"] = json::array({{{"name", "m"}, {"range", {4, 7}}, {"albedo", 0.5}, {"extinction", "csv:data/ext.csv"}}});
  j["lights"][0]["spectrum"] = "csv:data/ext.csv*2";
  const Scene s = load_scene(write_scene(dir, j, "sub/scene.json"));
  EXPECT_EQ(s.medium.material[3], Medium::kEmpty);
  EXPECT_EQ(s.medium.material[4], 0);
  EXPECT_EQ(s.medium.material[7], 0);
  EXPECT_DOUBLE_EQ(s.medium.materials[0].sigma_t_per_unit.eval(550.0), 1.5);
  EXPECT_TRUE(s.medium.bounds_max.isApprox(Eigen::Vector3d(0.25, 0.25, 0.5)));
  // The light's csv path is made absolute so the spec works from any folder.
  EXPECT_EQ(s.lights[0].spectrum_spec, "csv:" + (dir / "sub/data/ext.csv").string() + "*2");
  EXPECT_EQ(s.output, dir / "sub/out/x.exr");
}

TEST(SceneLoader, TransferFunctionImage) {
  ScratchDir dir;
  // 2 wide, 2 high: row 0 empty, row 1 a material with albedo 1, extinction 0.2·scale, g = 0.
  const std::vector<unsigned char> px{0, 0, 0, 0, 0, 0, 255, 51, 255, 255, 51, 255};
  auto out = OIIO::ImageOutput::create((dir / "tf.png").string());
  ASSERT_TRUE(out);
  ASSERT_TRUE(out->open((dir / "tf.png").string(), OIIO::ImageSpec(2, 2, 3, OIIO::TypeDesc::UINT8)));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, px.data()));
  ASSERT_TRUE(out->close());
  json j = base_scene();
  j.erase("materials");
  j["transfer_function"] = {{"image", "tf.png"}, {"extinction_scale", 50}, {"wavelength_range_nm", {400, 700}}};
  const Scene s = load_scene(write_scene(dir, j));
  ASSERT_EQ(s.medium.materials.size(), 1u);
  EXPECT_NEAR(s.medium.materials[0].sigma_t_per_unit.eval(500.0), 10.0, 1e-5);
  EXPECT_NEAR(s.medium.materials[0].anisotropy.eval(500.0), 0.999, 1e-9);
  // auto normalisation over 0..255: values ≥ 127.5 are row 1 (the sphere and nothing else).
  auto idx = [](int x, int y, int z) { return (static_cast<std::size_t>(z) * 16 + y) * 16 + x; };
  EXPECT_EQ(s.medium.material[idx(8, 8, 8)], 0);
  EXPECT_EQ(s.medium.material[idx(2, 8, 8)], Medium::kEmpty);
}

TEST(SceneLoader, HashIsStableAndFollowsTheText) {
  ScratchDir dir;
  json j = base_scene();
  const std::string h1 = load_scene(write_scene(dir, j)).hash;
  EXPECT_EQ(load_scene(write_scene(dir, j)).hash, h1);
  j["seed"] = 8;
  EXPECT_NE(load_scene(write_scene(dir, j)).hash, h1);
}

TEST(SceneLoaderErrors, MalformedJsonReportsLineAndColumn) {
  ScratchDir dir;
  const auto path = dir.write("bad.json", "{\n  \"samples\": 4,\n  \"seed\" 3\n}\n");
  const InputError e = load_error(path);
  EXPECT_EQ(e.input(), path.string());
  EXPECT_NE(e.reason().find("line 3, column"), std::string::npos) << e.what();
}

TEST(SceneLoaderErrors, MissingFile) {
  ScratchDir dir;
  EXPECT_THROW(load_scene(dir / "absent.json"), InputError);
}

TEST(SceneLoaderErrors, UnknownFields) {
  ScratchDir dir;
  json j = base_scene();
  j["sampels"] = 4;
  expect_error(dir, j, "sampels", "unknown field");
  j = base_scene();
  j["materials"][1]["albdo"] = 0.5;
  expect_error(dir, j, "materials[1].albdo", "unknown field");
  j = base_scene();
  j["camera"]["fov"] = 30;
  expect_error(dir, j, "camera.fov", "unknown field");
  j = base_scene();
  j["volume"]["dims"] = {16, 16, 16};  // raw-only field on a procedural volume
  expect_error(dir, j, "volume.dims", "unknown field");
}

TEST(SceneLoaderErrors, DuplicateKeys) {
  ScratchDir dir;
  const InputError e = load_error(dir.write("dup.json", R"({"samples": 4, "samples": 5})"));
  EXPECT_NE(e.reason().find("duplicate key \"samples\""), std::string::npos) << e.what();
}

// A number beyond the range of a double makes nlohmann::json throw out_of_range, not parse_error:
// found by fuzz_scene (a 300-digit number); it must still be an InputError naming where it is.
TEST(SceneLoaderErrors, NumberBeyondDouble) {
  ScratchDir dir;
  const auto huge = dir.write("huge.json", "{\n  \"samples\": 4,\n  \"seed\": 1e400\n}");
  EXPECT_EQ(load_error(huge).reason(), "number 1e400 at line 3, column 11 is beyond the range of a double");
  const auto digits = dir.write("digits.json", "{\"samples\": " + std::string(400, '9') + "}");
  EXPECT_EQ(load_error(digits).reason(),
            "number " + std::string(24, '9') + "... at line 1, column 13 is beyond the range of a double");
}

TEST(SceneLoaderErrors, WrongTypes) {
  ScratchDir dir;
  json j = base_scene();
  j["samples"] = "8";
  expect_error(dir, j, "samples", "must be an integer");
  j = base_scene();
  j["samples"] = 2.5;
  expect_error(dir, j, "samples", "must be an integer");
  j = base_scene();
  j["camera"]["position"] = {0, 0};
  expect_error(dir, j, "camera.position", "array of 3 numbers");
  j = base_scene();
  j["lights"][0]["direction"][1] = "up";
  expect_error(dir, j, "lights[0].direction[1]", "must be a number");
  j = base_scene();
  j["materials"][0]["albedo"] = json::array({0.5});
  expect_error(dir, j, "materials[0].albedo", "spectrum spec");
  j = base_scene();
  j["materials"] = json::object();
  expect_error(dir, j, "materials", "must be an array");
}

TEST(SceneLoaderErrors, OutOfRangeMaterialValues) {
  ScratchDir dir;
  json j = base_scene();
  j["materials"][0]["extinction"]["scale"] = -3;
  expect_error(dir, j, "materials[0].extinction.scale", "must be > 0 (got -3)");
  j = base_scene();
  j["materials"][1]["albedo"] = 1.5;
  expect_error(dir, j, "materials[1].albedo", "[0, 1]");
  j = base_scene();
  j["materials"][1]["albedo"] = {{"spectrum", "cc:19"}, {"scale", 3}};  // patch 19 (white) ≈ 0.9 → 2.7
  expect_error(dir, j, "materials[1].albedo", "[0, 1]");
  j = base_scene();
  j["materials"][0]["extinction"] = -1;
  expect_error(dir, j, "materials[0].extinction", "≥ 0");
  j = base_scene();
  j["materials"][0]["anisotropy"] = 1.0;
  expect_error(dir, j, "materials[0].anisotropy", "(-1, 1)");
  j = base_scene();
  j["materials"][0]["range"] = {150, 50};
  expect_error(dir, j, "materials[0].range", "lo must be ≤ hi");
  j = base_scene();
  j["materials"][1]["density"] = {{200, 1}, {100, 2}};
  expect_error(dir, j, "materials[1].density[1][0]", "strictly increasing");
  j = base_scene();
  j["materials"][1]["density"] = {{200, -1}};
  expect_error(dir, j, "materials[1].density[0][1]", "≥ 0");
  j = base_scene();
  j["materials"][1]["name"] = "cube";
  expect_error(dir, j, "materials[1].name", "duplicate material name");
  j = base_scene();
  j["materials"] = json::array();
  expect_error(dir, j, "materials", "at least one");
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

TEST(SceneLoaderErrors, VolumeAndTransferFunction) {
  ScratchDir dir;
  json j = base_scene();
  j["volume"]["type"] = "dicom";
  expect_error(dir, j, "volume.type", "\"raw\", \"nifti\", \"vdb\" or \"procedural\"");
  j = base_scene();
  j["volume"]["name"] = "teapot";
  expect_error(dir, j, "volume.name", "unknown procedural volume");
  j = base_scene();
  j["volume"]["resolution"] = 1;
  expect_error(dir, j, "volume.resolution", "must be in [2, 2048]");
  j = base_scene();
  j["volume"]["spacing"] = {1, 0, 1};
  expect_error(dir, j, "volume.spacing[1]", "must be > 0");
  j = base_scene();
  j["volume"] = {{"type", "raw"}, {"path", "v_2x2x2_uint8.raw"}, {"voxel_type", "uint12"}};
  expect_error(dir, j, "volume.voxel_type", "unknown voxel type");
  j = base_scene();
  j["volume"] = {{"type", "raw"}, {"path", "v_2x2x2_uint8.raw"}, {"endianness", "middle"}};
  expect_error(dir, j, "volume.endianness", "\"little\" or \"big\"");
  j = base_scene();
  j.erase("volume");
  expect_error(dir, j, "volume", "is required");
  j = base_scene();
  j["transfer_function"] = {{"image", "tf.png"}, {"extinction_scale", 1}};
  expect_error(dir, j, "transfer_function", "not both");
  j = base_scene();
  j.erase("materials");
  expect_error(dir, j, "materials", "is required");
  j.erase("materials");
  j["transfer_function"] = {{"image", "tf.png"}, {"extinction_scale", -5}};
  expect_error(dir, j, "transfer_function.extinction_scale", "must be > 0 (got -5)");
  j["transfer_function"] = {{"image", "absent.png"}, {"extinction_scale", 5}};
  expect_error(dir, j, "transfer_function.image", "absent.png: no such file");
  j = base_scene();
  j["normalisation"] = {{"min", 5}, {"max", 5}};
  expect_error(dir, j, "normalisation.max", "must be > min");
  // A missing raw file names the file itself.
  j = base_scene();
  j["volume"] = {{"type", "raw"}, {"path", "absent_2x2x2_uint8.raw"}};
  const auto path = write_scene(dir, j);
  try {
    load_scene(path);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), (dir / "absent_2x2x2_uint8.raw").string());
  }
}

// issue 11: deeply nested JSON crashed (SIGSEGV in nlohmann's recursive dump); now one InputError.
TEST(SceneLoader, RefusesJsonNestedTooDeeply) {
  ScratchDir dir;
  const std::string deep = "{\"description\": " + std::string(70000, '[') + std::string(70000, ']') + "}";
  const InputError e = load_error(dir.write("deep.json", deep));
  EXPECT_EQ(e.input(), (dir / "deep.json").string());
  EXPECT_NE(e.reason().find("nested deeper than"), std::string::npos) << e.what();
  EXPECT_NE(e.reason().find("line 1, column"), std::string::npos) << e.what();
  // Brackets inside strings do not count.
  json j = base_scene();
  j["description"] = std::string(1000, '[');
  EXPECT_NO_THROW(load_scene(write_scene(dir, j)));
}

// issue 11: a directory, a FIFO and a symlink loop all said "does not exist".
TEST(SceneLoader, SaysWhatANonRegularSceneIs) {
  ScratchDir dir;
  std::filesystem::create_directory(dir / "folder.json");
  EXPECT_NE(load_error(dir / "folder.json").reason().find("is a folder"), std::string::npos);
  ASSERT_EQ(::mkfifo((dir / "pipe.json").c_str(), 0600), 0);
  EXPECT_NE(load_error(dir / "pipe.json").reason().find("FIFO"), std::string::npos);  // and no hang
  std::filesystem::create_symlink(dir / "loop_b.json", dir / "loop_a.json");
  std::filesystem::create_symlink(dir / "loop_a.json", dir / "loop_b.json");
  EXPECT_NE(load_error(dir / "loop_a.json").reason().find("symbolic link loop"), std::string::npos);
  std::filesystem::create_symlink(dir / "nowhere.json", dir / "dangling.json");
  EXPECT_NE(load_error(dir / "dangling.json").reason().find("does not exist"), std::string::npos);
  EXPECT_NE(load_error(dir / "absent.json").reason().find("no such file"), std::string::npos);
  EXPECT_NE(load_error("/dev/null").reason().find("character device"), std::string::npos);
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

// issue 11: an extinction (or extinction × density) beyond what the tracker can step through
// passed validation and the render never ended.
TEST(SceneLoader, RefusesExtinctionTheTrackerCannotRepresent) {
  ScratchDir dir;
  json j = base_scene();
  j["materials"][1]["extinction"] = 1e39;  // beyond float
  expect_error(dir, j, "materials[1].extinction", "extinction × density reaches");
  j = base_scene();
  j["materials"][1]["extinction"] = 2e6;
  expect_error(dir, j, "materials[1].extinction", "per unit length");
  j = base_scene();
  j["materials"][0]["extinction"] = 1000;
  j["materials"][0]["density"] = 5000;  // 5e6 per unit
  expect_error(dir, j, "materials[0].extinction", "extinction × density reaches");
  j = base_scene();
  j["materials"][1]["density"] = {{200, 0.5}, {255, 1e300}};
  expect_error(dir, j, "materials[1].density[1][1]", "must be at most");
  // The bound itself is fine, and an extinction outside any voxel's material costs nothing.
  j = base_scene();
  j["materials"][1]["extinction"] = 1e6;
  EXPECT_NO_THROW(load_scene(write_scene(dir, j)));
}

// issue 11: command-line values obey exactly the scene's ranges (--width 20000 bypassed 16384,
// --seed -1 wrapped, --width 1e9 exited 1).
TEST(SceneLoader, CommandLineOverridesObeyTheSceneRanges) {
  EXPECT_EQ(scene_integer_override("640", "camera.width", "--width"), 640);
  EXPECT_EQ(scene_integer_override("16384", "camera.height", "--height"), 16384);
  EXPECT_EQ(scene_integer_override("1099511627776", "samples", "--spp"), std::int64_t{1} << 40);
  EXPECT_EQ(scene_seed_override("18446744073709551615", "--seed"), 18446744073709551615ULL);
  auto error = [](auto f) {
    try {
      f();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error([] { scene_integer_override("20000", "camera.width", "--width"); }),
            "--width: must be in [1, 16384] (got 20000)");
  EXPECT_EQ(error([] { scene_integer_override("0", "camera.height", "--height"); }),
            "--height: must be in [1, 16384] (got 0)");
  EXPECT_NE(error([] { scene_integer_override("1e9", "camera.width", "--width"); }).find("--width: must be an integer"),
            std::string::npos);
  EXPECT_NE(error([] { scene_integer_override("8.7", "samples", "--spp"); }).find("--spp: must be an integer"),
            std::string::npos);
  EXPECT_NE(error([] { scene_integer_override("many", "samples", "--spp"); }).find("--spp: must be an integer"),
            std::string::npos);
  EXPECT_EQ(error([] { scene_integer_override("1099511627777", "samples", "--spp"); }),
            "--spp: must be in [1, 1099511627776] (got 1099511627777)");
  EXPECT_NE(error([] { scene_seed_override("-1", "--seed"); }).find("--seed: must be an integer ≥ 0"), std::string::npos);
  EXPECT_NE(error([] { scene_seed_override("18446744073709551616", "--seed"); }).find("--seed: must be an integer"),
            std::string::npos);
}

// -D KEY=VALUE (prizma-render): a field set by its path, typed by the field it replaces, checked as
// the file is, errors named by the option; the overrides change the scene's hash.
TEST(SceneLoader, DefineOverridesAnyFieldByItsPath) {
  ScratchDir dir;
  const auto path = write_scene(dir, base_scene());
  const Scene plain = load_scene(path);
  const Scene s = load_scene(path, {parse_scene_override("camera.fov_deg=30"), parse_scene_override("lights.sky.spectrum=A"),
                                    parse_scene_override("lights[0].direction=[0, 1, 0]"),
                                    parse_scene_override("bins=linear:400:700:4"), parse_scene_override("seed=9"),
                                    parse_scene_override("normalization={\"min\": 0, \"max\": 255}")});
  EXPECT_DOUBLE_EQ(s.camera.fov_y_deg, 30.0);
  EXPECT_EQ(s.lights[1].spectrum_spec, "A");
  EXPECT_TRUE(s.lights[0].direction.isApprox(Eigen::Vector3d(0, 1, 0)));
  EXPECT_EQ(s.settings.bins, spectral::BinLayout::linear(400, 700, 4));
  EXPECT_EQ(s.settings.seed, 9u);
  EXPECT_NE(s.hash, plain.hash);
  EXPECT_EQ(load_scene(path, {parse_scene_override("seed=9")}).hash, load_scene(path, {parse_scene_override("seed=9")}).hash);
  auto error = [&](const std::vector<std::string>& defines) {
    try {
      std::vector<SceneOverride> o;
      for (const auto& d : defines) o.push_back(parse_scene_override(d));
      load_scene(path, o);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error({"camera.fov_deg=300"}), "-D camera.fov_deg: must be in (0, 180) (got 300)");
  EXPECT_EQ(error({"samples=many"}), "-D samples: must be an integer (got string \"many\")");
  EXPECT_EQ(error({"lights.fill.spectrum=A"}), "-D lights.fill.spectrum: lights has no element named \"fill\" (2 elements: side, sky)");
  EXPECT_EQ(error({"seed=1", "seed=2"}), "-D seed: is given twice");
  EXPECT_EQ(error({"lights[0].spectrum=A", "lights.side.spectrum=A"}), "-D lights.side.spectrum: is given twice");
  EXPECT_EQ(error({"camera..width=3"}).rfind("-D camera..width: malformed key", 0), 0u);
  EXPECT_EQ(error({"seed"}).rfind("-D seed: expected KEY=VALUE", 0), 0u);
  EXPECT_EQ(error({"normalization=\"auto\"", "normalisation=\"auto\""}),
            "-D normalization: give normalisation or normalization (the same field), not both");
}

}  // namespace
}  // namespace prizma::render
