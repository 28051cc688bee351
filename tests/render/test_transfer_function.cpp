// Transfer functions: density ramps, value normalisation, material validation, build_medium (first
// match wins, empty voxels, world bounds from anisotropic spacing) and VPT transfer-function images.
#include "prizma/render/transfer_function.h"

#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <sys/stat.h>
#include <zlib.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>

#include "prizma/render/environment_map.h"
#include "prizma/spectral/error.h"
#include "test_scene_util.h"

namespace prizma::render {
namespace {

using spectral::InputError;
using spectral::Spectrum;
using testing::ScratchDir;

Material grey(const std::string& name, double albedo, double sigma_t, double g = 0.0) {
  Material m;
  m.name = name;
  m.albedo = Spectrum::constant(albedo);
  m.sigma_t_per_unit = Spectrum::constant(sigma_t);
  m.anisotropy = Spectrum::constant(g);
  return m;
}

Volume line_volume(std::vector<float> values) {
  Volume v;
  v.dims = {static_cast<int>(values.size()), 1, 1};
  v.values = std::move(values);
  v.source = "test";
  return v;
}

TEST(DensityRamp, PiecewiseLinearAndClampedAtTheEnds) {
  DensityRamp r;
  EXPECT_EQ(r.eval(-5.0), 1.0);  // no points: density 1
  r.values = {10.0, 20.0, 40.0};
  r.densities = {0.0, 2.0, 1.0};
  EXPECT_DOUBLE_EQ(r.eval(0.0), 0.0);
  EXPECT_DOUBLE_EQ(r.eval(15.0), 1.0);
  EXPECT_DOUBLE_EQ(r.eval(20.0), 2.0);
  EXPECT_DOUBLE_EQ(r.eval(30.0), 1.5);
  EXPECT_DOUBLE_EQ(r.eval(100.0), 1.0);
}

TEST(ValueNormalisation, AutoUsesFiniteMinAndMax) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const ValueNormalisation n = auto_normalisation(line_volume({3.0f, nan, -1.0f, 7.0f}));
  EXPECT_EQ(n.min, -1.0);
  EXPECT_EQ(n.max, 7.0);
  EXPECT_DOUBLE_EQ(n.to_unit(3.0), 0.5);
  EXPECT_DOUBLE_EQ(n.to_unit(100.0), 1.0);
  EXPECT_DOUBLE_EQ(n.from_unit(0.25), 1.0);
  // A constant volume still maps without dividing by zero.
  const ValueNormalisation c = auto_normalisation(line_volume({2.0f, 2.0f}));
  EXPECT_DOUBLE_EQ(c.to_unit(2.0), 0.0);
  EXPECT_THROW(auto_normalisation(line_volume({nan})), InputError);
}

TEST(ValidateMaterial, RejectsOutOfRangeSpectra) {
  EXPECT_NO_THROW(validate_material(grey("a", 1.0, 0.0, 0.9), "m"));
  try {
    validate_material(grey("a", 1.2, 1.0), "scene.json: materials[0]");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), "scene.json: materials[0].albedo");
    EXPECT_NE(e.reason().find("1.2"), std::string::npos) << e.what();
  }
  try {
    validate_material(grey("a", 0.5, -3.0), "m");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), "m.extinction");
  }
  try {
    validate_material(grey("a", 0.5, 1.0, -1.0), "m");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), "m.anisotropy");
  }
  // A tabulated albedo that leaves [0, 1] at one sample.
  Material t = grey("t", 0.5, 1.0);
  t.albedo = Spectrum({400.0, 500.0, 600.0}, {0.2, 1.01, 0.3});
  EXPECT_THROW(validate_material(t, "m"), InputError);
}

TEST(BuildMedium, FirstMatchWinsUnmatchedAndNanAreEmpty) {
  TransferFunction tf;
  tf.materials = {grey("a", 0.5, 1.0), grey("b", 0.9, 2.0)};
  MaterialRule ra;
  ra.value_lo = 10.0;
  ra.value_hi = 20.0;
  ra.material = 0;
  MaterialRule rb;
  rb.value_lo = 15.0;
  rb.value_hi = 30.0;
  rb.material = 1;
  rb.density.values = {15.0, 30.0};
  rb.density.densities = {0.0, 3.0};
  tf.rules = {ra, rb};
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const Medium m = build_medium(line_volume({5.0f, 10.0f, 18.0f, 20.0f, 25.0f, 30.0f, 31.0f, nan, 15.0f}), tf, "t");
  const std::vector<std::uint16_t> expected_material{Medium::kEmpty, 0, 0, 0, 1, 1, Medium::kEmpty, Medium::kEmpty, 0};
  EXPECT_EQ(m.material, expected_material);
  EXPECT_FLOAT_EQ(m.density[1], 1.0f);
  EXPECT_FLOAT_EQ(m.density[4], 2.0f);  // ramp 0 → 3 over 15..30 at 25
  EXPECT_FLOAT_EQ(m.density[5], 3.0f);
  EXPECT_FLOAT_EQ(m.density[0], 0.0f);
  EXPECT_EQ(m.materials.size(), 2u);
  EXPECT_EQ(m.materials[1].name, "b");
}

TEST(BuildMedium, ZeroDensityIsEmpty) {
  TransferFunction tf;
  tf.materials = {grey("a", 0.5, 1.0)};
  MaterialRule r;
  r.density.values = {0.0, 1.0};
  r.density.densities = {0.0, 1.0};
  tf.rules = {r};
  const Medium m = build_medium(line_volume({-1.0f, 0.5f}), tf, "t");
  EXPECT_EQ(m.material[0], Medium::kEmpty);
  EXPECT_EQ(m.material[1], 0);
  EXPECT_FLOAT_EQ(m.density[1], 0.5f);
}

TEST(BuildMedium, AnisotropicSpacingGivesBoundsWithLargestSideOne) {
  Volume v;
  v.dims = {10, 20, 5};
  v.spacing = {2.0, 1.0, 1.0};  // extents 20, 20, 5
  v.values.assign(v.voxel_count(), 1.0f);
  TransferFunction tf;
  tf.materials = {grey("a", 0.5, 1.0)};
  tf.rules = {MaterialRule{}};
  const Medium m = build_medium(v, tf, "t");
  EXPECT_EQ(m.dims, v.dims);
  EXPECT_TRUE(m.bounds_min.isApprox(Eigen::Vector3d(-0.5, -0.5, -0.125)));
  EXPECT_TRUE(m.bounds_max.isApprox(Eigen::Vector3d(0.5, 0.5, 0.125)));
  v.spacing = {1.0, 1.0, 8.0};  // extents 10, 20, 40
  const Medium m2 = build_medium(v, tf, "t");
  EXPECT_TRUE(m2.bounds_max.isApprox(Eigen::Vector3d(0.125, 0.25, 0.5)));
  EXPECT_TRUE(m2.bounds_min.isApprox(-m2.bounds_max));
}

TEST(BuildMedium, RejectsTooManyMaterialsAndBadRules) {
  TransferFunction tf;
  tf.materials.assign(65535, grey("a", 0.5, 1.0));
  EXPECT_THROW(build_medium(line_volume({1.0f}), tf, "t"), InputError);
  tf.materials.resize(65534);  // the largest count an index below kEmpty can address
  EXPECT_NO_THROW(build_medium(line_volume({1.0f}), tf, "t"));
  tf.materials.resize(1);
  MaterialRule r;
  r.material = 3;
  tf.rules = {r};
  EXPECT_THROW(build_medium(line_volume({1.0f}), tf, "t"), InputError);
}

// Writes an 8-bit RGB PNG of width w, height h from rows of (R, G, B) bytes.
void write_png(const std::filesystem::path& path, int w, int h, const std::vector<unsigned char>& rgb) {
  auto out = OIIO::ImageOutput::create(path.string());
  ASSERT_TRUE(out);
  ASSERT_TRUE(out->open(path.string(), OIIO::ImageSpec(w, h, 3, OIIO::TypeDesc::UINT8)));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, rgb.data()));
  ASSERT_TRUE(out->close());
}

TEST(TransferFunctionImage, RowsBecomeMaterialsAndRules) {
  ScratchDir dir;
  // 3 columns (λ centres 450, 550, 650 nm over 400–700), 4 rows:
  //   row 0: G = 0 everywhere → empty;  rows 1, 2: identical → one material;  row 3: another.
  const std::vector<unsigned char> px{
      10, 0, 128, 20, 0, 128, 30, 0, 128,        // row 0
      0, 255, 0, 128, 255, 128, 255, 255, 255,  // row 1
      0, 255, 0, 128, 255, 128, 255, 255, 255,  // row 2
      200, 51, 128, 200, 51, 128, 200, 51, 128  // row 3
  };
  const auto path = dir / "tf.png";
  write_png(path, 3, 4, px);
  ValueNormalisation norm;
  norm.min = 0.0;
  norm.max = 300.0;  // row y ↔ value 100·y
  const TransferFunction tf = read_transfer_function_image(path, 50.0, 400.0, 700.0, norm, "tf");
  ASSERT_EQ(tf.materials.size(), 2u);
  const Material& a = tf.materials[0];
  EXPECT_EQ(a.name, "row1");
  EXPECT_NEAR(a.albedo.eval(450.0), 0.0, 1e-9);
  EXPECT_NEAR(a.albedo.eval(550.0), 128.0 / 255.0, 1e-6);
  EXPECT_NEAR(a.albedo.eval(650.0), 1.0, 1e-9);
  EXPECT_NEAR(a.sigma_t_per_unit.eval(500.0), 50.0, 1e-6);
  EXPECT_NEAR(a.anisotropy.eval(450.0), -0.999, 1e-9);  // B = 0 → g = −1, clamped
  EXPECT_NEAR(a.anisotropy.eval(550.0), 2.0 * 128.0 / 255.0 - 1.0, 1e-6);
  EXPECT_NEAR(a.anisotropy.eval(650.0), 0.999, 1e-9);
  const Material& b = tf.materials[1];
  EXPECT_NEAR(b.albedo.eval(600.0), 200.0 / 255.0, 1e-6);
  EXPECT_NEAR(b.sigma_t_per_unit.eval(600.0), 10.0, 1e-5);  // 51/255 · 50

  // Values → materials through the rows (boundaries halfway between rows: 50, 150, 250).
  const Medium m = build_medium(line_volume({0.0f, 49.0f, 51.0f, 100.0f, 200.0f, 249.0f, 251.0f, 300.0f, 1000.0f, -5.0f}),
                                tf, "t");
  const std::vector<std::uint16_t> expected{Medium::kEmpty, Medium::kEmpty, 0, 0, 0, 0, 1, 1, 1, Medium::kEmpty};
  EXPECT_EQ(m.material, expected);
}

TEST(TransferFunctionImage, Errors) {
  ScratchDir dir;
  ValueNormalisation norm;
  EXPECT_THROW(read_transfer_function_image(dir / "absent.png", 1.0, 400, 700, norm, "tf"), InputError);
  dir.write("bad.png", "not a png");
  EXPECT_THROW(read_transfer_function_image(dir / "bad.png", 1.0, 400, 700, norm, "tf"), InputError);
  write_png(dir / "ok.png", 2, 2, std::vector<unsigned char>(12, 100));
  EXPECT_THROW(read_transfer_function_image(dir / "ok.png", 0.0, 400, 700, norm, "tf"), InputError);
  EXPECT_THROW(read_transfer_function_image(dir / "ok.png", 1.0, 700, 400, norm, "tf"), InputError);
  try {
    read_transfer_function_image(dir / "absent.png", 1.0, 400, 700, norm, "scene.json: transfer_function.image");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), "scene.json: transfer_function.image");
  }
}

// The message of the InputError that reading `path` as a transfer function throws.
std::string tf_error(const std::filesystem::path& path) {
  try {
    read_transfer_function_image(path, 1.0, 400, 700, ValueNormalisation{}, "tf");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

// issue 11: a 150-byte PNG whose header claims 8192×8192 cost 1.2 GB before it was refused.
TEST(TransferFunctionImage, RefusesDimensionsTheFileCannotHold) {
  ScratchDir dir;
  write_png(dir / "small.png", 2, 2, std::vector<unsigned char>(12, 100));
  std::ifstream in(dir / "small.png", std::ios::binary);
  std::string png((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(png.size(), 33u);
  ASSERT_EQ(png.substr(12, 4), "IHDR");
  auto put_be32 = [&](std::size_t at, std::uint32_t v) {
    for (int k = 0; k < 4; ++k) png[at + k] = static_cast<char>((v >> (24 - 8 * k)) & 0xff);
  };
  put_be32(16, 8192);  // width
  put_be32(20, 8192);  // height
  put_be32(29, static_cast<std::uint32_t>(crc32(0, reinterpret_cast<const Bytef*>(png.data() + 12), 17)));
  const std::string msg = tf_error(dir.write("huge.png", png));
  EXPECT_NE(msg.find("8192×8192"), std::string::npos) << msg;  // before the fix: read (1.2 GB), then refused
  // Within the pixel limit but more than the file can hold.
  put_be32(16, 2048);
  put_be32(20, 2048);
  put_be32(29, static_cast<std::uint32_t>(crc32(0, reinterpret_cast<const Bytef*>(png.data() + 12), 17)));
  const std::string small = tf_error(dir.write("claims.png", png));
  EXPECT_NE(small.find("claims 2048×2048×3 pixels, more than its"), std::string::npos) << small;
  // A real image larger than a transfer function can be.
  write_png(dir / "wide.png", 4096, 2048, std::vector<unsigned char>(4096 * 2048 * 3, 7));
  EXPECT_NE(tf_error(dir / "wide.png").find("at most 4194304 pixels"), std::string::npos);
}

// issue 11: a transfer-function image of /dev/zero (or a FIFO) blocked forever.
TEST(TransferFunctionImage, RefusesNonRegularFiles) {
  ScratchDir dir;
  EXPECT_NE(tf_error("/dev/zero").find("tf: image /dev/zero: is a character device"), std::string::npos)
      << tf_error("/dev/zero");
  ASSERT_EQ(::mkfifo((dir / "pipe.png").c_str(), 0600), 0);
  EXPECT_NE(tf_error(dir / "pipe.png").find("FIFO"), std::string::npos);
}

// issue 11: a truncated PNG printed libpng's own lines; its message is now part of the one error.
TEST(TransferFunctionImage, TruncatedPngIsOneError) {
  ScratchDir dir;
  std::vector<unsigned char> px(64 * 64 * 3);
  for (std::size_t i = 0; i < px.size(); ++i) px[i] = static_cast<unsigned char>((i * 7919) % 251);
  write_png(dir / "full.png", 64, 64, px);
  std::ifstream in(dir / "full.png", std::ios::binary);
  const std::string png((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto cut = dir.write("cut.png", png.substr(0, png.size() / 2));
  ::testing::internal::CaptureStderr();
  const std::string msg = tf_error(cut);
  const std::string printed = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(msg.find("cannot read image"), std::string::npos) << msg;
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  EXPECT_EQ(printed, "");
}

// issue 21: a TIFF or a JPEG cut in half rendered with exit 0, the rows the reader could not decode
// left as zeros (OpenImageIO's read_image returned true with the error recorded). Every format
// through both readers of scene images (transfer function, environment map): refused, on one line
// naming the file, with nothing printed besides.
TEST(PictureReading, TruncatedImagesOfEveryFormatAreRefused) {
  ScratchDir dir;
  constexpr int kW = 48, kH = 256;  // 256 rows: a TIFF of many strips, one reader message per strip
  std::vector<unsigned char> px(static_cast<std::size_t>(kW) * kH * 3);
  for (std::size_t i = 0; i < px.size(); ++i) px[i] = static_cast<unsigned char>(1 + (i * 7919) % 250);
  for (const std::string ext : {"tif", "jpg", "png", "exr"}) {
    const auto full = dir / ("full." + ext);
    write_png(full, kW, kH, px);
    std::ifstream in(full, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto cut = dir.write("cut." + ext, bytes.substr(0, bytes.size() / 2));
    EXPECT_EQ(tf_error(full), "no error") << ext;
    EXPECT_NO_THROW(EnvironmentMap::load(full, 0.0, "sky")) << ext;

    ::testing::internal::CaptureStderr();
    const std::string msg = tf_error(cut);
    std::string env_msg = "no error";
    try {
      EnvironmentMap::load(cut, 0.0, "sky");
    } catch (const InputError& e) {
      env_msg = e.what();
    }
    const std::string printed = ::testing::internal::GetCapturedStderr();
    for (const std::string& m : {msg, env_msg}) {
      EXPECT_NE(m.find("cannot read image " + cut.string() + ": "), std::string::npos) << ext << ": " << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
      EXPECT_LT(m.size(), 800u) << m;  // the first reader messages, the rest counted
    }
    EXPECT_EQ(printed, "") << ext;
  }
}

}  // namespace
}  // namespace prizma::render
