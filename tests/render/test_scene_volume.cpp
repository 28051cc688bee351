// load_scene's volume and transfer function sections (renderer/src/scene/scene_volume.cpp): paths
// relative to the scene file, transfer-function images, and their errors.
#include "scene_loader_test_support.h"

namespace prizma::render {
namespace {

using namespace scene_test;

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

TEST(SceneLoaderErrors, VolumeAndTransferFunction) {
  ScratchDir dir;
  expect_errors(dir, {
      {"volume.type", "\"raw\", \"nifti\", \"vdb\" or \"procedural\"", [](json& j) { j["volume"]["type"] = "dicom"; }},
      {"volume.name", "unknown procedural volume", [](json& j) { j["volume"]["name"] = "teapot"; }},
      {"volume.resolution", "must be in [2, 2048]", [](json& j) { j["volume"]["resolution"] = 1; }},
      {"volume.spacing[1]", "must be > 0", [](json& j) { j["volume"]["spacing"] = {1, 0, 1}; }},
      {"volume.voxel_type", "unknown voxel type",
       [](json& j) { j["volume"] = {{"type", "raw"}, {"path", "v_2x2x2_uint8.raw"}, {"voxel_type", "uint12"}}; }},
      {"volume.endianness", "\"little\" or \"big\"",
       [](json& j) { j["volume"] = {{"type", "raw"}, {"path", "v_2x2x2_uint8.raw"}, {"endianness", "middle"}}; }},
      {"volume", "is required", [](json& j) { j.erase("volume"); }},
      {"transfer_function", "not both",
       [](json& j) { j["transfer_function"] = {{"image", "tf.png"}, {"extinction_scale", 1}}; }},
      {"materials", "is required", [](json& j) { j.erase("materials"); }},
  });
  json j = base_scene();
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

}  // namespace
}  // namespace prizma::render
