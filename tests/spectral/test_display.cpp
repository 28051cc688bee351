// DisplayTransform over OpenColorIO with data/ocio/config.ocio: white, grey, the XYZ → sRGB matrix
// against libspectral's, the RGB-space matrices re-derived here from the primaries, errors and $OCIO.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "prizma/spectral/colour.h"
#include "prizma/spectral/display.h"
#include "prizma/spectral/error.h"

namespace fs = std::filesystem;
using namespace prizma::spectral;

namespace {

const fs::path kConfig = fs::path(PRIZMA_TEST_DATA_DIR) / "ocio" / "config.ocio";

// D65 white, Y = 1, as printed in IEC 61966-2-1 (X = 0.9505, Z = 1.0890).
const Eigen::Vector3d kWhiteXyz(0.9505, 1.0, 1.0890);

DisplayTransform make(const std::string& display, const std::string& colour_space = "",
                      const fs::path& config = kConfig) {
  DisplayOptions o;
  o.config = config;
  o.display = display;
  o.colour_space = colour_space;
  return DisplayTransform(o);
}

Eigen::Vector3d apply1(const DisplayTransform& t, const Eigen::Vector3d& xyz) {
  float px[3] = {static_cast<float>(xyz[0]), static_cast<float>(xyz[1]), static_cast<float>(xyz[2])};
  t.apply(px, 1);
  return {px[0], px[1], px[2]};
}

// Normalised primary matrix (RGB → XYZ) from chromaticities, SMPTE RP 177: re-derived here
// independently of data/ocio/derive_matrices.py.
Eigen::Matrix3d npm(const Eigen::Vector2d& r, const Eigen::Vector2d& g, const Eigen::Vector2d& b,
                    const Eigen::Vector2d& w) {
  auto xyz = [](const Eigen::Vector2d& c) { return Eigen::Vector3d(c[0] / c[1], 1.0, (1 - c[0] - c[1]) / c[1]); };
  Eigen::Matrix3d p;
  p.col(0) = xyz(r);
  p.col(1) = xyz(g);
  p.col(2) = xyz(b);
  const Eigen::Vector3d s = p.colPivHouseholderQr().solve(xyz(w));
  return p * s.asDiagonal();
}

const Eigen::Vector2d kD65(0.3127, 0.3290);
const Eigen::Vector2d kAcesWhite(0.32168, 0.33767);
Eigen::Matrix3d npm_709() { return npm({0.64, 0.33}, {0.30, 0.60}, {0.15, 0.06}, kD65); }
Eigen::Matrix3d npm_p3() { return npm({0.680, 0.320}, {0.265, 0.690}, {0.150, 0.060}, kD65); }
Eigen::Matrix3d npm_2020() { return npm({0.708, 0.292}, {0.170, 0.797}, {0.131, 0.046}, kD65); }
Eigen::Matrix3d npm_ap1() { return npm({0.713, 0.293}, {0.165, 0.830}, {0.128, 0.044}, kAcesWhite); }

// Restores $OCIO on scope exit.
class OcioEnvGuard {
 public:
  OcioEnvGuard() {
    if (const char* v = std::getenv("OCIO")) m_old = v;
  }
  ~OcioEnvGuard() {
    if (m_old) {
      ::setenv("OCIO", m_old->c_str(), 1);
    } else {
      ::unsetenv("OCIO");
    }
  }

 private:
  std::optional<std::string> m_old;
};

}  // namespace

TEST(Display, D65WhiteIsSrgbWhite) {
  const auto t = make("sRGB");
  const Eigen::Vector3d rgb = apply1(t, kWhiteXyz);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(rgb[c], 1.0, 1e-3) << c;
}

TEST(Display, SrgbCurveEncodes) {
  // 18 % grey encodes to 0.4614 (IEC 61966-2-1 curve), 0.001 lies on the linear segment (×12.92).
  const auto t = make("sRGB");
  for (double y : {0.18, 0.5, 0.001}) {
    const Eigen::Vector3d rgb = apply1(t, y * kWhiteXyz);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(rgb[c], srgb_encode(y), 2e-4) << y << " " << c;
  }
  EXPECT_NEAR(srgb_encode(0.18), 0.46135612, 1e-6);
}

TEST(Display, OtherDisplaysKeepWhiteAndUseTheirCurves) {
  const auto p3 = make("Display P3");
  const auto rec2020 = make("Rec.2020");
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(apply1(p3, kWhiteXyz)[c], 1.0, 1e-3);
    EXPECT_NEAR(apply1(rec2020, kWhiteXyz)[c], 1.0, 1e-3);
    // Grey: sRGB curve for P3, pure 2.4 power (BT.1886, zero black) for Rec.2020.
    EXPECT_NEAR(apply1(p3, 0.18 * kWhiteXyz)[c], srgb_encode(0.18), 2e-4);
    EXPECT_NEAR(apply1(rec2020, 0.18 * kWhiteXyz)[c], std::pow(0.18, 1 / 2.4), 2e-4);
  }
}

TEST(Display, XyzToLinearSrgbMatchesLibspectral) {
  const auto t = make("", "Linear sRGB");
  std::mt19937 rng(20240601);
  std::uniform_real_distribution<float> u(0.0f, 1.2f);
  for (int k = 0; k < 200; ++k) {
    const Eigen::Vector3d xyz(u(rng), u(rng), u(rng));  // float-representable inputs
    const Eigen::Vector3d expected = xyz_to_linear_srgb(xyz);
    const Eigen::Vector3d got = apply1(t, xyz);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], expected[c], 1e-5) << k << " " << c;
  }
}

TEST(Display, AcesCgOfWhiteIsOne) {
  const auto t = make("", "ACEScg");
  const Eigen::Vector3d rgb = apply1(t, kWhiteXyz);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(rgb[c], 1.0, 1e-3) << c;
}

TEST(Display, LinearSpacesMatchMatricesDerivedFromPrimaries) {
  // Expected: RGB_dst = NPM_dst^-1 · [Bradford D65 → dst white] · NPM_709 · xyz_to_linear_srgb(XYZ).
  const Eigen::Matrix3d from_709 = npm_709();
  const Eigen::Vector3d d65 = xy_to_xyz(0.3127, 0.3290);
  const Eigen::Vector3d aces_white = xy_to_xyz(0.32168, 0.33767);
  struct Case {
    const char* space;
    Eigen::Matrix3d m;
  };
  const std::vector<Case> cases = {
      {"Linear Display P3", npm_p3().inverse() * from_709},
      {"Linear Rec.2020", npm_2020().inverse() * from_709},
      {"ACEScg", npm_ap1().inverse() * bradford_adaptation(d65, aces_white) * from_709},
  };
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (const auto& c : cases) {
    const auto t = make("", c.space);
    for (int k = 0; k < 50; ++k) {
      const Eigen::Vector3d xyz(u(rng), u(rng), u(rng));
      const Eigen::Vector3d expected = c.m * xyz_to_linear_srgb(xyz);
      const Eigen::Vector3d got = apply1(t, xyz);
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(got[i], expected[i], 1e-5) << c.space << " " << k << " " << i;
    }
  }
}

TEST(Display, PrimariesMapToAxes) {
  // The XYZ of a space's red primary (its own NPM's first column) has no green or blue in that space;
  // depends only on the published chromaticities (and Bradford for AP1, whose primaries are given
  // under the ACES white).
  const Eigen::Vector3d d65 = xy_to_xyz(0.3127, 0.3290);
  const Eigen::Vector3d aces_white = xy_to_xyz(0.32168, 0.33767);
  const Eigen::Matrix3d to_d65 = bradford_adaptation(aces_white, d65);
  struct Case {
    const char* space;
    Eigen::Matrix3d npm;
    Eigen::Matrix3d adapt;
  };
  const std::vector<Case> cases = {{"Linear sRGB", npm_709(), Eigen::Matrix3d::Identity()},
                                   {"Linear Display P3", npm_p3(), Eigen::Matrix3d::Identity()},
                                   {"Linear Rec.2020", npm_2020(), Eigen::Matrix3d::Identity()},
                                   {"ACEScg", npm_ap1(), to_d65}};
  for (const auto& c : cases) {
    const auto t = make("", c.space);
    for (int p = 0; p < 3; ++p) {
      // Through libspectral's 4-decimal IEC matrix: off-axis residue up to ~1e-4.
      const Eigen::Vector3d rgb = apply1(t, c.adapt * c.npm.col(p));
      for (int i = 0; i < 3; ++i) EXPECT_NEAR(rgb[i], i == p ? 1.0 : 0.0, 5e-4) << c.space << " " << p << " " << i;
    }
  }
}

TEST(Display, AcesCgMatchesPublishedMatrix) {
  // Linear Rec.709 → ACEScg (Bradford), 8 decimals as in ASWF MaterialX mx_transform_color.glsl.
  Eigen::Matrix3d published;
  published << 0.61309740, 0.33952315, 0.04737945,
               0.07019372, 0.91635388, 0.01345240,
               0.02061559, 0.10956977, 0.86981463;
  const auto t = make("", "ACEScg");
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int k = 0; k < 20; ++k) {
    const Eigen::Vector3d rgb(u(rng), u(rng), u(rng));
    const Eigen::Vector3d got = apply1(t, linear_srgb_to_xyz(rgb));
    const Eigen::Vector3d expected = published * rgb;
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(got[i], expected[i], 1e-5) << k << " " << i;
  }
}

TEST(Display, ListsDisplaysAndSpaces) {
  const auto t = make("sRGB");
  EXPECT_EQ(t.displays(), (std::vector<std::string>{"sRGB", "Display P3", "Rec.2020"}));
  const auto spaces = t.colour_spaces();
  for (const char* s : {"CIE-XYZ-D65", "Linear sRGB", "ACEScg", "Linear Display P3", "Linear Rec.2020", "sRGB",
                        "Display P3", "Rec.2020", "Raw"}) {
    EXPECT_NE(std::find(spaces.begin(), spaces.end(), s), spaces.end()) << s;
  }
  EXPECT_EQ(t.config_path(), kConfig);
  EXPECT_NE(t.description().find("sRGB"), std::string::npos);
  EXPECT_NE(t.description().find("Standard"), std::string::npos);
}

TEST(Display, UnknownNamesListValidOnes) {
  try {
    make("sRGB-ish");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("sRGB-ish"), std::string::npos) << msg;
    EXPECT_NE(msg.find("sRGB, Display P3, Rec.2020"), std::string::npos) << msg;
  }
  try {
    make("", "ProPhoto");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("ACEScg"), std::string::npos) << e.what();
  }
  DisplayOptions o;
  o.config = kConfig;
  o.view = "Filmic";
  try {
    DisplayTransform t(o);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("Standard"), std::string::npos) << e.what();
  }
}

TEST(Display, UnreadableConfigIsInputErrorNamingIt) {
  const fs::path missing = fs::temp_directory_path() / "prizma-no-such-config.ocio";
  try {
    make("sRGB", "", missing);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), missing.string());
  }
  const fs::path garbage = fs::temp_directory_path() / ("prizma-garbage-" + std::to_string(::getpid()) + ".ocio");
  std::ofstream(garbage) << "this: is: not [ an ocio config\n";
  try {
    make("sRGB", "", garbage);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), garbage.string());
    EXPECT_NE(std::string(e.what()).find("cannot load OCIO config"), std::string::npos) << e.what();
  }
  fs::remove(garbage);
}

TEST(Display, OcioEnvironmentVariableIsRespected) {
  OcioEnvGuard guard;
  // A tiny config whose XYZ space doubles the values, so the result shows which config was used.
  const fs::path custom = fs::temp_directory_path() / ("prizma-test-" + std::to_string(::getpid()) + ".ocio");
  std::ofstream(custom) << R"(ocio_profile_version: 2
roles:
  default: lin
  reference: lin
  scene_linear: lin
  data: lin
file_rules:
  - !<Rule> {name: Default, colorspace: default}
displays:
  Test Display:
    - !<View> {name: Standard, colorspace: lin}
colorspaces:
  - !<ColorSpace>
    name: lin
  - !<ColorSpace>
    name: CIE-XYZ-D65
    to_scene_reference: !<MatrixTransform> {matrix: [2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1]}
)";
  ::setenv("OCIO", custom.c_str(), 1);
  EXPECT_EQ(default_ocio_config(), custom);
  DisplayOptions o;
  o.display = "Test Display";
  const DisplayTransform t(o);
  EXPECT_EQ(t.config_path(), custom);
  EXPECT_EQ(t.displays(), std::vector<std::string>{"Test Display"});
  const Eigen::Vector3d rgb = apply1(t, {0.25, 0.5, 1.0});
  EXPECT_NEAR(rgb[0], 0.5, 1e-6);
  EXPECT_NEAR(rgb[2], 2.0, 1e-6);
  // The default display "sRGB" does not exist there.
  EXPECT_THROW(DisplayTransform(DisplayOptions{}), InputError);

  // Empty $OCIO means "not set": the bundled config.
  ::setenv("OCIO", "", 1);
  EXPECT_EQ(default_ocio_config().filename(), "config.ocio");
  EXPECT_NE(default_ocio_config(), custom);
  fs::remove(custom);
}

TEST(Display, ApplyIsThreadSafeAndDeterministic) {
  const auto t = make("sRGB");
  std::vector<float> base(3 * 4096);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (auto& v : base) v = u(rng);
  std::vector<float> serial = base;
  t.apply(serial.data(), serial.size() / 3);
  std::vector<std::vector<float>> outs(4, base);
  std::vector<std::thread> threads;
  for (auto& o : outs) threads.emplace_back([&t, &o] { t.apply(o.data(), o.size() / 3); });
  for (auto& th : threads) th.join();
  for (const auto& o : outs) EXPECT_EQ(o, serial);
  for (float v : serial) ASSERT_TRUE(std::isfinite(v));
}

TEST(Display, MovedTransformStillWorks) {
  auto a = make("sRGB");
  DisplayTransform b = std::move(a);
  EXPECT_NEAR(apply1(b, kWhiteXyz)[1], 1.0, 1e-3);
}
