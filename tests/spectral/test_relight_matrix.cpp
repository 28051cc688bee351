// RelightMatrix and relight_image against values computed by hand from the CIE 1931 table.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <cmath>

#include "prizma/spectral/relight_image.h"
#include "prizma/spectral/relight_matrix.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/colour.h"
#include "spectral/relight_test_util.h"

namespace prizma::spectral {
namespace {

using spectral::BinLayout;

// The transport of the test image: a different constant per bin and pixel, in [0.05, 0.95].
float transport(int layer, int pixel, int bin) {
  return static_cast<float>(0.05 + 0.9 * std::fmod(0.137 * (bin + 1) + 0.291 * pixel + 0.5 * layer, 1.0));
}

std::vector<LightSpectrum> lights(std::initializer_list<const char*> specs) {
  std::vector<LightSpectrum> out;
  for (const char* s : specs) out.push_back(parse_light_spectrum(s));
  return out;
}

// Expected XYZ at every pixel of a one-layer image under `light`, by hand: per bin the trapezoid
// integral of light × cmf (1 nm CIE 1931 table), normalised so that Σ_i W_y,i = 1 (white → Y = 1).
std::vector<Eigen::Vector3d> hand_relight(const spectral::SpectralImage& img,
                                          const std::function<double(double)>& light) {
  static const test::Table cmf = test::read_table("cie1931_xyz2deg_1nm.csv");
  const int n = img.bins.size();
  Eigen::MatrixXd w(3, n);
  for (int c = 0; c < 3; ++c)
    for (int i = 0; i < n; ++i) w(c, i) = test::hand_weight(cmf, c, light, img.bins.lo_nm(i), img.bins.hi_nm(i));
  w /= w.row(1).sum();
  std::vector<Eigen::Vector3d> out;
  for (std::size_t p = 0; p < img.pixel_count(); ++p) {
    Eigen::VectorXd t(n);
    for (int i = 0; i < n; ++i) t[i] = img.lights[0].data[p * static_cast<std::size_t>(n) + static_cast<std::size_t>(i)];
    out.push_back(w * t);
  }
  return out;
}

void expect_near_image(const XyzImage& got, const std::vector<Eigen::Vector3d>& want, double rel_tol) {
  ASSERT_EQ(got.pixel_count(), want.size());
  for (std::size_t p = 0; p < want.size(); ++p)
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(got.xyz[3 * p + static_cast<std::size_t>(c)], want[p][c], rel_tol * std::max(1e-3, std::abs(want[p][c])))
          << "pixel " << p << " channel " << c;
}

class KnownTransport : public ::testing::TestWithParam<int> {};

// Equal-energy light E: the weights are plain CMF integrals per bin. Checked for bin counts that
// take the fixed-size kernels (12, 32) and the general one (7).
TEST_P(KnownTransport, EqualEnergyLightMatchesHandIntegral) {
  const BinLayout bins = BinLayout::linear(400.0, 700.0, GetParam());
  const auto img = test::make_image(5, 3, bins, {"key"}, transport);
  const XyzImage got = relight_image(img, RelightMatrix(bins, lights({"E"}), {}));
  // Tolerance: float accumulation (1e-6) plus the 0.05 nm trapezoid rule (< 1e-5 relative).
  expect_near_image(got, hand_relight(img, [](double) { return 1.0; }), 2e-5);
}

INSTANTIATE_TEST_SUITE_P(BinCounts, KnownTransport, ::testing::Values(7, 12, 32));

TEST(RelightMatrix, NarrowBandGaussianMatchesHandIntegral) {
  const BinLayout bins = BinLayout::linear(400.0, 700.0, 12);
  const auto img = test::make_image(4, 2, bins, {"key"}, transport);
  const XyzImage got = relight_image(img, RelightMatrix(bins, lights({"gaussian:550:5"}), {}));
  // gaussian:550:5 = exp(−4 ln2 (λ−550)²/5²), peak 1 (spectrum_spec.h). The light lies in one
  // 25 nm bin, so every pixel is that bin's value times the XYZ of the light normalised to Y = 1.
  // Tolerance 2e-3: the library tabulates the gaussian; the hand integral uses the exact curve.
  expect_near_image(got, hand_relight(img, [](double l) { return std::exp(-4.0 * std::log(2.0) * (l - 550.0) * (l - 550.0) / 25.0); }),
                    2e-3);
}

TEST(RelightMatrix, SpikyF11MatchesHandIntegral) {
  static const test::Table f11 = test::read_table("illuminant_F11.csv");
  const BinLayout bins = BinLayout::linear(400.0, 700.0, 12);
  const auto img = test::make_image(4, 2, bins, {"key"}, transport);
  const XyzImage got = relight_image(img, RelightMatrix(bins, lights({"F11"}), {}));
  expect_near_image(got, hand_relight(img, [](double l) { return f11.eval(0, l); }), 2e-5);
}

TEST(RelightMatrix, AllLightsOffGiveBlack) {
  const BinLayout bins = BinLayout::linear(400.0, 700.0, 16);
  const auto img = test::make_image(3, 3, bins, {"key", "back"}, transport);
  const XyzImage got = relight_image(img, RelightMatrix(bins, lights({"off", "off"}), {}));
  for (float v : got.xyz) EXPECT_EQ(v, 0.0f);
}

TEST(RelightMatrix, ScalingALightScalesTheImage) {
  const BinLayout bins = BinLayout::linear(400.0, 700.0, 16);
  const auto img = test::make_image(3, 3, bins, {"key"}, transport);
  const XyzImage one = relight_image(img, RelightMatrix(bins, lights({"D65"}), {}));
  const XyzImage scaled = relight_image(img, RelightMatrix(bins, lights({"D65*2.5"}), {}));
  for (std::size_t k = 0; k < one.xyz.size(); ++k) EXPECT_NEAR(scaled.xyz[k], 2.5f * one.xyz[k], 1e-6f * 2.5f * std::abs(one.xyz[k]) + 1e-7f);
  // Exposure +1 EV doubles it as well.
  RelightOptions plus_one;
  plus_one.exposure_ev = 1.0;
  const XyzImage brighter = relight_image(img, RelightMatrix(bins, lights({"D65"}), plus_one));
  for (std::size_t k = 0; k < one.xyz.size(); ++k) EXPECT_NEAR(brighter.xyz[k], 2.0f * one.xyz[k], 1e-6f * std::abs(one.xyz[k]) + 1e-7f);
}

TEST(RelightMatrix, TwoLightsAdd) {
  const BinLayout bins = BinLayout::linear(400.0, 700.0, 32);
  const auto img = test::make_image(4, 3, bins, {"key", "back"}, transport);
  const XyzImage key = relight_image(img, RelightMatrix(bins, lights({"A", "off"}), {}));
  const XyzImage back = relight_image(img, RelightMatrix(bins, lights({"off", "F11*0.5"}), {}));
  const XyzImage both = relight_image(img, RelightMatrix(bins, lights({"A", "F11*0.5"}), {}));
  for (std::size_t k = 0; k < both.xyz.size(); ++k) EXPECT_NEAR(both.xyz[k], key.xyz[k] + back.xyz[k], 1e-5f);
  // And the sum differs from either part (the test can fail).
  EXPECT_GT(std::abs(both.xyz[1] - key.xyz[1]), 0.01f);
}

TEST(RelightMatrix, WhiteUnderEachLightHasUnitLuminance) {
  const BinLayout bins = BinLayout::linear(380.0, 780.0, 20);
  for (const char* spec : {"D65", "A", "F11", "LED-B1", "gaussian:600:30"}) {
    const RelightMatrix m(bins, lights({spec}), {});
    EXPECT_NEAR(m.mix_white_xyz().y(), 1.0, 1e-12) << spec;
  }
  // Absolute units keep the light's own scale: D65's table is 100 near 560 nm, so Y is far above 1.
  RelightOptions absolute;
  absolute.units = spectral::LightUnits::Absolute;
  EXPECT_GT(RelightMatrix(bins, lights({"D65"}), absolute).mix_white_xyz().y(), 100.0);
}

TEST(RelightMatrix, BradfordAdaptationTakesTheMixWhiteToD65) {
  const BinLayout bins = BinLayout::linear(380.0, 780.0, 20);
  RelightOptions adapt;
  adapt.adapt_to_d65 = true;
  const RelightMatrix m(bins, lights({"A"}), adapt);
  // A white surface (T = 1) under illuminant A comes out with D65's chromaticity at Y = 1.
  const Eigen::Vector3d white = m.light(0).rowwise().sum();
  const Eigen::Vector3d d65 = spectral::white_d65();
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(white[c], d65[c], 1e-9);
  // Without adaptation, A's white is far from D65 (x ≈ 0.4476 for CIE A, CIE 015 table).
  const RelightMatrix plain(bins, lights({"A"}), {});
  EXPECT_NEAR(spectral::chromaticity(plain.mix_white_xyz()).x(), 0.4476, 0.003);
}

TEST(RelightMatrix, ResultDoesNotDependOnThreadCount) {
  // The kernel is per pixel: one thread and all threads give bit-identical images.
  const BinLayout bins = BinLayout::linear(400.0, 700.0, 32);
  const auto img = test::make_image(64, 37, bins, {"key", "back"}, transport);
  const RelightMatrix m(bins, lights({"D65", "A"}), {});
  const XyzImage a = relight_image(img, m);
  XyzImage b;
  {
    tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
    b = relight_image(img, m);
  }
  EXPECT_EQ(a.xyz, b.xyz);
}

TEST(LightSpectrum, ParsesScalesAndOff) {
  const LightSpectrum a = parse_light_spectrum("D65*0.5*4");
  EXPECT_DOUBLE_EQ(a.scale, 2.0);
  EXPECT_FALSE(a.off);
  EXPECT_TRUE(parse_light_spectrum("off").off);
  EXPECT_TRUE(parse_light_spectrum("D65*0").off);
  EXPECT_THROW(parse_light_spectrum("D66"), spectral::InputError);
  EXPECT_THROW(parse_light_spectrum("D65*-1"), spectral::InputError);
  EXPECT_THROW(parse_light_spectrum(""), spectral::InputError);
}

// issue 21: "D65*1e39" gave +inf weights, NaN pixels and a black image with exit 0. A light's scale is
// at most kMaxLightScale (the product of its factors); just inside, at the largest exposure, every
// weight and every relit value is finite and the image is not black.
TEST(LightSpectrum, ScaleAboveTheBoundIsRefused) {
  for (const char* spec : {"D65*1e39", "D65*1e13", "D65*1e7*1e6", "A*1e300*1e300"}) {
    try {
      parse_light_spectrum(spec, {"--light key", {}});
      ADD_FAILURE() << spec;
    } catch (const spectral::InputError& e) {
      EXPECT_EQ(e.input(), "--light key");
      EXPECT_NE(e.reason().find("is above 1e+12"), std::string::npos) << e.what();
    }
  }
  EXPECT_DOUBLE_EQ(parse_light_spectrum("D65*1e6*1e6").scale, spectral::kMaxLightScale);
  const BinLayout bins = BinLayout::linear(400.0, 700.0, 16);
  const auto img = test::make_image(3, 3, bins, {"key"}, transport);
  RelightOptions brightest;
  brightest.exposure_ev = 64.0;
  const XyzImage got = relight_image(img, RelightMatrix(bins, lights({"D65*1e12"}), brightest));
  for (float v : got.xyz) {
    EXPECT_TRUE(std::isfinite(v)) << v;
    EXPECT_GT(v, 1e30f);  // T ≥ 0.05 at 1e12 × 2^64
  }
}

// The same net for absolute units, whose weights follow the table's own values: a constant 1e30
// at +64 EV cannot be held by a float and is refused, naming the light; relative, it is fine.
TEST(RelightMatrix, RefusesWeightsAFloatCannotHold) {
  const BinLayout bins = BinLayout::linear(400.0, 700.0, 16);
  RelightOptions absolute;
  absolute.units = spectral::LightUnits::Absolute;
  absolute.exposure_ev = 64.0;
  try {
    RelightMatrix(bins, lights({"D65", "1e30"}), absolute);
    ADD_FAILURE() << "no error";
  } catch (const spectral::InputError& e) {
    EXPECT_EQ(e.input(), "light");
    EXPECT_NE(e.reason().find("\"1e30\": its relight weights"), std::string::npos) << e.what();
  }
  RelightOptions relative;
  relative.exposure_ev = 64.0;
  EXPECT_TRUE(RelightMatrix(bins, lights({"D65", "1e30"}), relative).stacked().allFinite());
}

}  // namespace
}  // namespace prizma::spectral
