// Outputs other tools read right (issue 25 items 12 and 16): an XYZ EXR in OpenEXR's own convention
// (R, G, B channels holding X, Y, Z with XYZ's chromaticities), read by OpenEXR's RGBA reader and by
// OpenImageIO as the colours that were written; PNGs with the cICP chunk of their display; TIFF and
// JPEG with the provenance (in their image description) and Exif's colour space.
#include <gtest/gtest.h>

#include <OpenEXR/ImfChromaticities.h>
#include <OpenEXR/ImfRgbaFile.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenImageIO/imageio.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "prizma/spectral/output_image.h"
#include "spectral/relight_test_util.h"

namespace prizma::relight {
namespace {

namespace fs = std::filesystem;

// Three saturated colours and a grey, as XYZ: what a reader that ignores chromaticities must still
// tell apart (channels X, Y, Z were read as one grey by RGBA readers).
spectral::XyzImage four_colours() {
  spectral::XyzImage img;
  img.width = 4;
  img.height = 1;
  img.xyz = {0.41f, 0.21f, 0.02f, 0.36f, 0.72f, 0.12f, 0.18f, 0.07f, 0.95f, 0.50f, 0.5f, 0.5f};
  return img;
}

TEST(OutputInterop, XyzExrIsReadByOpenExrsRgbaReaderAsItsColours) {
  const fs::path dir = spectral::test::scratch_dir("output-xyz-rgba");
  const spectral::XyzImage img = four_colours();
  spectral::write_output_image(dir / "xyz.exr", img, spectral::OutputOptions{}, {});

  Imf::RgbaInputFile in((dir / "xyz.exr").c_str());
  EXPECT_EQ(in.channels(), Imf::WRITE_RGB);  // R, G, B present: not a luminance-only (grey) file
  ASSERT_TRUE(Imf::hasChromaticities(in.header()));
  const Imf::Chromaticities c = Imf::chromaticities(in.header());
  // OpenEXR's XYZ convention: red (1, 0), green (0, 1), blue (0, 0), white (⅓, ⅓).
  EXPECT_EQ(c.red, Imath::V2f(1, 0));
  EXPECT_EQ(c.green, Imath::V2f(0, 1));
  EXPECT_EQ(c.blue, Imath::V2f(0, 0));
  EXPECT_NEAR(c.white.x, 1.0f / 3, 1e-7f);
  EXPECT_NEAR(c.white.y, 1.0f / 3, 1e-7f);
  std::vector<Imf::Rgba> px(4);
  in.setFrameBuffer(px.data(), 1, 4);
  in.readPixels(0, 0);
  // The reader's RGB → XYZ matrix for these chromaticities is the identity: RGB are the X, Y, Z.
  const Imath::M44f to_xyz = Imf::RGBtoXYZ(c, 1.0f);
  for (int p = 0; p < 4; ++p) {
    const Imath::V3f rgb(px[p].r, px[p].g, px[p].b);
    Imath::V3f xyz;
    to_xyz.multDirMatrix(rgb, xyz);
    for (int k = 0; k < 3; ++k) {
      const float want = img.xyz[static_cast<std::size_t>(3 * p + k)];
      EXPECT_NEAR(xyz[k], want, 2e-3f * want + 1e-6f) << "pixel " << p << " component " << k;  // half precision
    }
  }
  // Not a grey: the red and the blue pixel differ in R and B by far more than half's rounding.
  EXPECT_GT(px[0].r - px[2].r, 0.2f);
  EXPECT_GT(px[2].b - px[0].b, 0.9f);
  fs::remove_all(dir);
}

TEST(OutputInterop, XyzExrIsReadByOpenImageIoAsRgbWithXyzChromaticities) {
  const fs::path dir = spectral::test::scratch_dir("output-xyz-oiio");
  const spectral::XyzImage img = four_colours();
  spectral::write_output_image(dir / "xyz.exr", img, spectral::OutputOptions{}, {});
  auto in = OIIO::ImageInput::open((dir / "xyz.exr").string());
  ASSERT_TRUE(in) << OIIO::geterror();
  const OIIO::ImageSpec& spec = in->spec();
  ASSERT_EQ(spec.nchannels, 3);
  EXPECT_EQ(spec.channel_name(0), "R");
  EXPECT_EQ(spec.channel_name(1), "G");
  EXPECT_EQ(spec.channel_name(2), "B");
  const OIIO::ParamValue* chroma = spec.find_attribute("chromaticities");
  ASSERT_NE(chroma, nullptr);
  const float* xy = static_cast<const float*>(chroma->data());
  const float want_xy[8] = {1, 0, 0, 1, 0, 0, 1.0f / 3, 1.0f / 3};
  for (int i = 0; i < 8; ++i) EXPECT_NEAR(xy[i], want_xy[i], 1e-7f) << i;
  std::vector<float> px(12);
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, px.data()));
  for (std::size_t i = 0; i < px.size(); ++i) EXPECT_EQ(px[i], img.xyz[i]) << i;  // float: exactly
  fs::remove_all(dir);
}

struct PngChunk {
  std::string type;
  std::string data;
  bool crc_ok = false;
};

// The chunks of a PNG file, in order, each with its CRC checked independently of libpng.
std::vector<PngChunk> png_chunks(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<PngChunk> out;
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  auto u32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (int k = 0; k < 4; ++k) v = (v << 8) | static_cast<unsigned char>(bytes[at + static_cast<std::size_t>(k)]);
    return v;
  };
  for (std::size_t at = 8; at + 12 <= bytes.size();) {
    const std::uint32_t n = u32(at);
    PngChunk c;
    c.type = bytes.substr(at + 4, 4);
    c.data = bytes.substr(at + 8, n);
    std::uint32_t crc = 0xFFFFFFFFu;  // CRC-32 (ISO 3309) of type and data, bit by bit
    for (std::size_t i = at + 4; i < at + 8 + n; ++i) {
      crc ^= static_cast<unsigned char>(bytes[i]);
      for (int k = 0; k < 8; ++k) crc = (crc & 1u) ? (crc >> 1) ^ 0xEDB88320u : crc >> 1;
    }
    c.crc_ok = (crc ^ 0xFFFFFFFFu) == u32(at + 8 + n);
    out.push_back(c);
    at += 12 + n;
  }
  return out;
}

TEST(OutputInterop, DisplayPngsCarryTheCicpChunkOfTheirDisplay) {
  // PNG 3rd edition cICP (ITU-T H.273): primaries 1 BT.709 / 12 P3-D65 / 9 BT.2020, transfer 13
  // sRGB for sRGB and Display P3, 1 (BT.709 / BT.2020 with the BT.1886 display, a 2.4 power) for the
  // shipped Rec.2020 display, matrix 0 (RGB), full range 1; after IHDR, before IDAT, valid CRC,
  // beside the ICC profile (iCCP), and the file still reads.
  const fs::path dir = spectral::test::scratch_dir("output-cicp");
  spectral::XyzImage img = four_colours();
  const std::pair<const char*, std::string> cases[] = {
      {"sRGB", std::string("\x01\x0d\x00\x01", 4)},
      {"Display P3", std::string("\x0c\x0d\x00\x01", 4)},
      {"Rec.2020", std::string("\x09\x01\x00\x01", 4)}};
  for (const auto& [display, want] : cases) {
    spectral::OutputOptions opts;
    opts.display.display = display;
    for (int bits : {8, 16}) {
      opts.bit_depth = bits;
      const fs::path path = dir / (std::string(display) + std::to_string(bits) + ".png");
      spectral::write_output_image(path, img, opts, {});
      const std::vector<PngChunk> chunks = png_chunks(path);
      ASSERT_GE(chunks.size(), 3u) << path;
      EXPECT_EQ(chunks[0].type, "IHDR");
      EXPECT_EQ(chunks[1].type, "cICP") << path;
      EXPECT_EQ(chunks[1].data, want) << path;
      bool iccp = false, idat_after = false;
      for (std::size_t i = 0; i < chunks.size(); ++i) {
        EXPECT_TRUE(chunks[i].crc_ok) << path << " chunk " << chunks[i].type;
        iccp = iccp || chunks[i].type == "iCCP";
        idat_after = idat_after || (chunks[i].type == "IDAT" && i > 1);
      }
      EXPECT_TRUE(iccp) << path;
      EXPECT_TRUE(idat_after) << path;
      auto in = OIIO::ImageInput::open(path.string());
      ASSERT_TRUE(in) << OIIO::geterror();
      std::vector<float> px(12);
      EXPECT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, px.data())) << in->geterror();
    }
  }
  fs::remove_all(dir);
}

TEST(OutputInterop, TiffAndJpegCarryTheProvenanceAndExifColourSpace) {
  // relight.md promises prizma:* provenance in every output: TIFF and JPEG hold it as one JSON
  // object in their image description (OpenImageIO drops prizma:* keys there). A JPEG's Exif
  // ColorSpace says sRGB (1) or "uncalibrated" (0xFFFF: another space, the ICC profile says which).
  const fs::path dir = spectral::test::scratch_dir("output-provenance");
  const spectral::ImageMetadata md = {{"Software", "prizma-relight test"}, {"prizma:source", "cs.exr"},
                            {"prizma:lights", R"([{"name":"key","spectrum":"F11*0.2"}])"}, {"prizma:display", "x"}};
  for (const char* ext : {".tif", ".jpg"}) {
    for (const char* display : {"sRGB", "Display P3"}) {
      spectral::OutputOptions opts;
      opts.display.display = display;
      const fs::path path = dir / (std::string(display) + ext);
      spectral::write_output_image(path, four_colours(), opts, md);
      auto in = OIIO::ImageInput::open(path.string());
      ASSERT_TRUE(in) << OIIO::geterror();
      const OIIO::ImageSpec& spec = in->spec();
      EXPECT_EQ(spec.get_string_attribute("Software"), "prizma-relight test") << path;
      const nlohmann::json j = nlohmann::json::parse(spec.get_string_attribute("ImageDescription"), nullptr, false);
      ASSERT_TRUE(j.is_object()) << path << ": " << spec.get_string_attribute("ImageDescription");
      EXPECT_EQ(j.value("prizma:source", ""), "cs.exr") << path;
      EXPECT_EQ(j.value("prizma:lights", ""), R"([{"name":"key","spectrum":"F11*0.2"}])") << path;
      EXPECT_EQ(j.value("prizma:display", ""), "x") << path;
      EXPECT_FALSE(j.contains("Software"));
      // JPEG only: OpenImageIO 2.4's TIFF writer given Exif:ColorSpace leaves out ImageLength.
      const int exif = std::string(ext) == ".jpg" ? (std::string(display) == "sRGB" ? 1 : 0xFFFF) : 0;
      EXPECT_EQ(spec.get_int_attribute("Exif:ColorSpace"), exif) << path;
    }
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace prizma::relight
