// ICC profiles of display-encoded outputs (issue 15 part 3): PNG, TIFF and JPEG written by
// write_output_image carry a profile of their display, read back here with OpenImageIO and parsed
// with Little CMS independently of the writer: the primaries and white it holds (undoing the
// profile's own D50 adaptation, its chad tag) are the display's published ones, its curve is the
// display's, and a Display P3 file's profile is not sRGB's.
#include <gtest/gtest.h>
#include <lcms2.h>

#include <OpenImageIO/imageio.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "prizma/spectral/output_image.h"
#include "spectral/relight_test_util.h"

namespace prizma::spectral {
namespace {

namespace fs = std::filesystem;

struct ReadProfile {
  std::vector<unsigned char> bytes;
  std::array<double, 8> xy{};  // red, green, blue, white, as the display has them (before D50)
  double decode_half = 0.0;    // the red curve at 0.5
  int parametric_type = 0;     // 0: tabulated
  std::string description;
};

// The ICC profile OpenImageIO finds in `path`, parsed with Little CMS.
ReadProfile read_profile(const fs::path& path) {
  ReadProfile out;
  auto in = OIIO::ImageInput::open(path.string());
  EXPECT_TRUE(in) << path << ": " << OIIO::geterror();
  if (!in) return out;
  const OIIO::ParamValue* p = in->spec().find_attribute("ICCProfile");
  EXPECT_NE(p, nullptr) << path << ": no ICC profile";
  if (p == nullptr) return out;
  const auto* data = static_cast<const unsigned char*>(p->data());
  out.bytes.assign(data, data + p->type().size());
  in->close();

  cmsHPROFILE profile = cmsOpenProfileFromMem(out.bytes.data(), static_cast<cmsUInt32Number>(out.bytes.size()));
  EXPECT_NE(profile, nullptr) << path << ": Little CMS cannot open its profile";
  if (profile == nullptr) return out;
  EXPECT_EQ(cmsGetColorSpace(profile), cmsSigRgbData);
  EXPECT_EQ(cmsGetDeviceClass(profile), cmsSigDisplayClass);
  // The chad tag: a 3×3 matrix, row-major (Little CMS reads it as 9 doubles).
  const auto* chad = static_cast<const cmsFloat64Number*>(cmsReadTag(profile, cmsSigChromaticAdaptationTag));
  const auto* wtpt = static_cast<const cmsCIEXYZ*>(cmsReadTag(profile, cmsSigMediaWhitePointTag));
  const cmsTagSignature colorants[3] = {cmsSigRedColorantTag, cmsSigGreenColorantTag, cmsSigBlueColorantTag};
  EXPECT_NE(chad, nullptr);
  EXPECT_NE(wtpt, nullptr);
  if (chad != nullptr && wtpt != nullptr) {
    Eigen::Matrix3d m;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) m(r, c) = chad[3 * r + c];
    const Eigen::Matrix3d undo = m.inverse();  // PCS (D50) → the display's own white
    for (int k = 0; k < 4; ++k) {
      const cmsCIEXYZ* v = k < 3 ? static_cast<const cmsCIEXYZ*>(cmsReadTag(profile, colorants[k])) : wtpt;
      EXPECT_NE(v, nullptr);
      if (v == nullptr) continue;
      const Eigen::Vector3d xyz = undo * Eigen::Vector3d(v->X, v->Y, v->Z);
      out.xy[static_cast<std::size_t>(2 * k)] = xyz[0] / xyz.sum();
      out.xy[static_cast<std::size_t>(2 * k + 1)] = xyz[1] / xyz.sum();
    }
  }
  if (const auto* trc = static_cast<const cmsToneCurve*>(cmsReadTag(profile, cmsSigRedTRCTag))) {
    out.decode_half = cmsEvalToneCurveFloat(trc, 0.5f);
    out.parametric_type = cmsGetToneCurveParametricType(trc);
  }
  char text[256] = {};
  if (cmsGetProfileInfoASCII(profile, cmsInfoDescription, "en", "US", text, sizeof text) > 0) out.description = text;
  cmsCloseProfile(profile);
  return out;
}

XyzImage grey(int w, int h) {
  XyzImage img;
  img.width = w;
  img.height = h;
  img.xyz.assign(static_cast<std::size_t>(w) * h * 3, 0.2f);
  return img;
}

struct Expected {
  const char* display;
  std::array<double, 8> xy;  // published primaries and D65
  double decode_half;
};
// sRGB: IEC 61966-2-1 (curve at 0.5: ((0.5 + 0.055) / 1.055)^2.4); Display P3: P3-D65 primaries
// (SMPTE EG 432-1) with the sRGB curve; Rec.2020: ITU-R BT.2020 primaries, a 2.4 power (BT.1886, black 0).
const Expected kSrgb{"sRGB", {0.64, 0.33, 0.30, 0.60, 0.15, 0.06, 0.3127, 0.3290}, 0.214041};
const Expected kP3{"Display P3", {0.680, 0.320, 0.265, 0.690, 0.150, 0.060, 0.3127, 0.3290}, 0.214041};
const Expected kRec2020{"Rec.2020", {0.708, 0.292, 0.170, 0.797, 0.131, 0.046, 0.3127, 0.3290}, 0.189465};

void expect_profile(const ReadProfile& got, const Expected& want, const std::string& what) {
  // 1e-3 in xy: the config's matrices are printed to 4–10 decimals, ICC stores s15Fixed16 numbers.
  for (std::size_t i = 0; i < 8; ++i) EXPECT_NEAR(got.xy[i], want.xy[i], 1e-3) << what << " xy[" << i << "]";
  EXPECT_NEAR(got.decode_half, want.decode_half, 1e-3) << what;
  EXPECT_EQ(got.description, want.display) << what;
}

TEST(OutputIcc, PngTiffAndJpegCarryTheirDisplaysProfile) {
  const fs::path dir = test::scratch_dir("output-icc");
  const XyzImage img = grey(16, 8);
  for (const Expected* want : {&kSrgb, &kP3, &kRec2020}) {
    for (const char* ext : {".png", ".tif", ".jpg"}) {
      const std::string name = std::string(want->display) + ext;
      OutputOptions opts;
      opts.display.display = want->display;
      write_output_image(dir / name, img, opts, {});
      const ReadProfile got = read_profile(dir / name);
      expect_profile(got, *want, name);
      // The standard curves are written as ICC parametric curves: sRGB's form (4), a pure power (1).
      EXPECT_EQ(got.parametric_type, want == &kRec2020 ? 1 : 4) << name;
    }
  }
  fs::remove_all(dir);
}

TEST(OutputIcc, DisplayP3PngIsNotTaggedAsSrgb) {
  const fs::path dir = test::scratch_dir("output-icc-p3");
  const XyzImage img = grey(4, 4);
  OutputOptions srgb, p3;
  p3.display.display = "Display P3";
  write_output_image(dir / "srgb.png", img, srgb, {});
  write_output_image(dir / "p3.png", img, p3, {});
  const ReadProfile a = read_profile(dir / "srgb.png"), b = read_profile(dir / "p3.png");
  ASSERT_FALSE(a.bytes.empty());
  ASSERT_FALSE(b.bytes.empty());
  EXPECT_NE(a.bytes, b.bytes);
  EXPECT_GT(std::abs(b.xy[0] - a.xy[0]), 0.03);  // red x: 0.680 against 0.640
  EXPECT_GT(std::abs(b.xy[3] - a.xy[3]), 0.05);  // green y: 0.690 against 0.600
  fs::remove_all(dir);
}

TEST(OutputIcc, TiffWithAProfileIsAWholeFile) {
  // OpenImageIO 2.4 wrote a TIFF without its ImageLength field when given oiio:ColorSpace; with
  // an ICC profile the file reads back whole, 8- and 16-bit.
  const fs::path dir = test::scratch_dir("output-icc-tiff");
  const XyzImage img = grey(24, 12);
  for (int bits : {8, 16}) {
    OutputOptions opts;
    opts.bit_depth = bits;
    opts.display.display = "Display P3";
    const fs::path path = dir / ("p3_" + std::to_string(bits) + ".tif");
    write_output_image(path, img, opts, {});
    auto in = OIIO::ImageInput::open(path.string());
    ASSERT_TRUE(in) << OIIO::geterror();
    EXPECT_EQ(in->spec().width, 24);
    EXPECT_EQ(in->spec().height, 12);
    std::vector<float> px(24 * 12 * 3);
    ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, px.data())) << in->geterror();
    EXPECT_GT(px[0], 0.0f);
  }
  fs::remove_all(dir);
}

TEST(OutputIcc, DisplayColourSpaceOfTheShippedDisplays) {
  spectral::DisplayOptions o;
  o.display = "Display P3";
  const auto cs = display_colour_space(spectral::DisplayTransform(o), "Display P3");
  ASSERT_TRUE(cs.has_value());
  EXPECT_TRUE(cs->curve_table.empty());
  EXPECT_EQ(cs->curve_type, 4);
  for (std::size_t i = 0; i < 8; ++i) EXPECT_NEAR(cs->chromaticities[i], kP3.xy[i], 1e-3) << i;
  // A curve that is none of the standard ones (here the identity of a linear colour space) is
  // written as the table.
  spectral::DisplayOptions lin;
  lin.colour_space = "Linear Display P3";
  const auto linear = display_colour_space(spectral::DisplayTransform(lin), "Linear Display P3");
  ASSERT_TRUE(linear.has_value());
  ASSERT_EQ(linear->curve_table.size(), 1024u);
  EXPECT_NEAR(linear->curve_table[512], 512.0 / 1023.0, 1e-4);
}

}  // namespace
}  // namespace prizma::spectral
