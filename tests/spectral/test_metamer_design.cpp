// Metamer design: the result must match under the match light and differ under the split light, as
// computed here independently of the design code (product spectra tabulated every 1 nm and
// integrated by ColorMatching, Lab relative to the light's white, CIEDE2000 from colour.h).
#include <gtest/gtest.h>

#include <vector>

#include "prizma/spectral/colour.h"
#include "prizma/spectral/colour_matching.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/metamer_design.h"
#include "prizma/spectral/spectrum_spec.h"
#include "spectral/independent_colour.h"

namespace prizma::spectral {
namespace {

using test::independent_delta_e;

TEST(MetamerDesign, MatchesUnderD65AndSplitsUnderA) {
  const Spectrum albedo = parse_spectrum("cc:4");
  const Spectrum d65 = parse_spectrum("D65");
  const Spectrum a = parse_spectrum("A");
  const MetamerResult result = design_metamer(albedo, d65, a);
  EXPECT_LT(independent_delta_e(albedo, result.reflectance, d65), 0.5);
  // D65 → A is a mild change of light, but a reflectance free to move within [0, 1] still splits far
  // (the design reached 32 when written).
  EXPECT_GT(independent_delta_e(albedo, result.reflectance, a), 15.0);
  EXPECT_NEAR(result.delta_e_split, independent_delta_e(albedo, result.reflectance, a), 0.05);
  EXPECT_GE(result.reflectance.min_value(), 0.0);
  EXPECT_LE(result.reflectance.max_value(), 1.0);
}

TEST(MetamerDesign, SplitsStronglyUnderANarrowBandLight) {
  const Spectrum albedo = parse_spectrum("cc:3");
  const Spectrum d65 = parse_spectrum("D65");
  const Spectrum f11 = parse_spectrum("F11");
  const MetamerResult result = design_metamer(albedo, d65, f11);
  EXPECT_LT(independent_delta_e(albedo, result.reflectance, d65), 0.5);
  // F11 is a three-band fluorescent lamp: far more room to split than D65 → A.
  EXPECT_GT(independent_delta_e(albedo, result.reflectance, f11), 20.0);
}

TEST(MetamerDesign, RespectsTighterBoundsAndIsSmooth) {
  MetamerOptions options;
  options.min_value = 0.1;
  options.max_value = 0.9;
  const Spectrum albedo = Spectrum::constant(0.5);
  const MetamerResult result = design_metamer(albedo, parse_spectrum("D65"), parse_spectrum("LED-B3"), options);
  EXPECT_GE(result.reflectance.min_value(), 0.1 - 1e-12);
  EXPECT_LE(result.reflectance.max_value(), 0.9 + 1e-12);
  EXPECT_LT(independent_delta_e(albedo, result.reflectance, parse_spectrum("D65")), 0.5);
  // Smooth: a cubic B-spline with knots ≥ 20 nm apart cannot change by more than the whole range
  // within 5 nm; steps between samples stay well below the bound width.
  const std::vector<double>& v = result.reflectance.values();
  for (size_t i = 1; i < v.size(); ++i) EXPECT_LT(std::abs(v[i] - v[i - 1]), 0.4) << "at sample " << i;
}

TEST(MetamerDesign, MatchesInTheBinsOfARender) {
  // Designing in a render's 16 bins: the match holds for the relighter's computation (relight
  // weights times bin averages), checked here with relight_weights directly.
  MetamerOptions options;
  options.colour.bins = BinLayout::linear(380.0, 780.0, 16);
  const Spectrum albedo = parse_spectrum("cc:9");
  const Spectrum d65 = parse_spectrum("D65");
  const MetamerResult result = design_metamer(albedo, d65, parse_spectrum("F11"), options);
  const auto m = relight_weights(ColorMatching::get(Observer::Cie1931_2deg), d65, options.colour.bins);
  const Eigen::Vector3d white = m.rowwise().sum();
  const auto averages = [&](const Spectrum& s) {
    const std::vector<double> v = s.bin_averages(options.colour.bins);
    return Eigen::VectorXd(Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size())));
  };
  const double de = delta_e2000(xyz_to_lab(m * averages(albedo), white), xyz_to_lab(m * averages(result.reflectance), white));
  EXPECT_LT(de, 0.5);
  EXPECT_GT(result.delta_e_split, 10.0);
}

TEST(MetamerDesign, RejectsAlbedoOutsideZeroOne) {
  try {
    design_metamer(Spectrum::constant(1.5), parse_spectrum("D65"), parse_spectrum("A"));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), "albedo");
    EXPECT_NE(e.reason().find("1.5"), std::string::npos) << e.what();
  }
}

TEST(MetamerDesign, PerfectWhiteHasNoMetamer) {
  // Within [0, 1] the only reflectance as bright as a perfect white is the perfect white itself.
  EXPECT_THROW(design_metamer(Spectrum::constant(1.0), parse_spectrum("D65"), parse_spectrum("F11")), InputError);
}

TEST(MetamerDesign, RejectsDarkLight) {
  try {
    design_metamer(Spectrum::constant(0.5), Spectrum::constant(0.0), parse_spectrum("A"));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), "match light");
  }
}

TEST(MetamerDesign, RejectsBadOptions) {
  MetamerOptions options;
  options.basis_size = 3;
  EXPECT_THROW(design_metamer(Spectrum::constant(0.5), parse_spectrum("D65"), parse_spectrum("A"), options), InputError);
  options = {};
  options.min_value = 0.8;
  options.max_value = 0.2;
  EXPECT_THROW(design_metamer(Spectrum::constant(0.5), parse_spectrum("D65"), parse_spectrum("A"), options), InputError);
}

TEST(MetamerDesign, HelpersAgreeWithIndependentComputation) {
  const Spectrum a = parse_spectrum("cc:7");
  const Spectrum b = parse_spectrum("cc:16");
  const Spectrum light = parse_spectrum("F2");
  const ColourSetting colour;
  EXPECT_NEAR(delta_e2000_under(a, b, light, colour), independent_delta_e(a, b, light), 0.02);
  const Eigen::Vector3d xyz = reflectance_xyz(Spectrum::constant(1.0), light, colour);
  EXPECT_NEAR(xyz.y(), 1.0, 1e-9);
  EXPECT_EQ(standard_report_lights().size(), 5u);
}

}  // namespace
}  // namespace prizma::spectral
