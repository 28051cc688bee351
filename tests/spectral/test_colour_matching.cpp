// Colour matching functions, published chromaticities and exact relight weights.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "prizma/spectral/colour.h"
#include "prizma/spectral/colour_matching.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/spectrum_spec.h"
#include "spectral/brute_force.h"

using namespace prizma::spectral;

namespace {

const ColorMatching& cie1931() { return ColorMatching::get(Observer::Cie1931_2deg); }

Eigen::Vector2d xy_of_light(const std::string& name) {
  return chromaticity(cie1931().integrate(parse_spectrum(name)));
}

using prizma::spectral::test_support::midpoint;

}  // namespace

TEST(ColorMatching, TablesAndRanges) {
  const auto& cmf = cie1931();
  EXPECT_DOUBLE_EQ(cmf.lo_nm(), 360.0);
  EXPECT_DOUBLE_EQ(cmf.hi_nm(), 830.0);
  EXPECT_EQ(cmf.observer(), Observer::Cie1931_2deg);
  // CIE 1931 ȳ(555 nm) = 1.0 and x̄(600 nm) = 1.0622 (CIE 015 table values).
  EXPECT_NEAR(cmf.y().eval(555.0), 1.0, 1e-6);
  EXPECT_NEAR(cmf.x().eval(600.0), 1.0622, 1e-4);
  // Σȳ·1 nm = 106.856917 (data/spectra/SOURCES.md); the trapezoid integral drops half the two end samples.
  EXPECT_NEAR(cmf.y().integrate(360, 830), 106.856917 - 0.5 * (3.917e-6 + 4.5181e-7), 1e-6);
  // The 2012 (CIE 170-2) tables start at 390 nm.
  EXPECT_DOUBLE_EQ(ColorMatching::get(Observer::Cie2012_2deg).lo_nm(), 390.0);
  EXPECT_DOUBLE_EQ(ColorMatching::get(Observer::Cie2012_10deg).lo_nm(), 390.0);
  EXPECT_DOUBLE_EQ(ColorMatching::get(Observer::Cie1964_10deg).hi_nm(), 830.0);
  // The same object every time (loaded once).
  EXPECT_EQ(&ColorMatching::get(Observer::Cie1964_10deg), &ColorMatching::get(Observer::Cie1964_10deg));
}

TEST(ColorMatching, ParseObserver) {
  EXPECT_EQ(parse_observer("1931"), Observer::Cie1931_2deg);
  EXPECT_EQ(parse_observer("CIE1931"), Observer::Cie1931_2deg);
  EXPECT_EQ(parse_observer("2deg"), Observer::Cie1931_2deg);
  EXPECT_EQ(parse_observer("1964"), Observer::Cie1964_10deg);
  EXPECT_EQ(parse_observer("10deg"), Observer::Cie1964_10deg);
  EXPECT_EQ(parse_observer("2012"), Observer::Cie2012_2deg);
  EXPECT_EQ(parse_observer("2006"), Observer::Cie2012_2deg);
  EXPECT_EQ(parse_observer("2012-2"), Observer::Cie2012_2deg);
  EXPECT_EQ(parse_observer("2012-10"), Observer::Cie2012_10deg);
  for (Observer o : {Observer::Cie1931_2deg, Observer::Cie1964_10deg, Observer::Cie2012_2deg, Observer::Cie2012_10deg}) {
    EXPECT_EQ(parse_observer(observer_name(o)), o) << observer_name(o);
  }
  try {
    (void)parse_observer("1932", "--cmf");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), "--cmf");
    EXPECT_NE(std::string(e.what()).find("\"1932\""), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("cie2012-10"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)parse_observer(""), InputError);
  EXPECT_THROW((void)parse_observer("2012-5"), InputError);
}

TEST(ColorMatching, PublishedChromaticities) {
  // CIE 015:2018 Table T.3 / T.1: D65 (0.31272, 0.32903), A (0.44757, 0.40745), 2° observer;
  // the published 4-decimal values are D65 (0.3127, 0.3290), A (0.4476, 0.4074). Computed here
  // from the tables in data/ (illuminant tables stop at 780 nm).
  const Eigen::Vector2d d65 = xy_of_light("D65");
  EXPECT_NEAR(d65[0], 0.31272, 5e-5);
  EXPECT_NEAR(d65[1], 0.32903, 5e-5);
  EXPECT_NEAR(d65[0], 0.3127, 1e-4);
  EXPECT_NEAR(d65[1], 0.3290, 1e-4);
  const Eigen::Vector2d a = xy_of_light("A");
  EXPECT_NEAR(a[0], 0.44757, 5e-5);
  EXPECT_NEAR(a[1], 0.40745, 5e-5);
  EXPECT_NEAR(a[0], 0.4476, 1e-4);
  EXPECT_NEAR(a[1], 0.4074, 1e-4);
  // Equal-energy E is at (1/3, 1/3) by construction of the CMFs (equal areas), to the table's rounding.
  const Eigen::Vector2d e = xy_of_light("E");
  EXPECT_NEAR(e[0], 1.0 / 3.0, 2e-4);
  EXPECT_NEAR(e[1], 1.0 / 3.0, 2e-4);
}

TEST(ColorMatching, PerfectWhiteUnderD65IsSrgbWhite) {
  const BinLayout bins;  // default 16 × 25 nm over 380–780 nm
  const auto m = relight_weights(cie1931(), parse_spectrum("D65"), bins);
  ASSERT_EQ(m.cols(), bins.size());
  const Eigen::VectorXd t = Eigen::VectorXd::Ones(bins.size());
  const Eigen::Vector3d xyz = m * t;
  EXPECT_NEAR(xyz[1], 1.0, 1e-12);  // RelativeToWhite: Σ_i M[1][i] = 1
  const Eigen::Vector3d rgb = xyz_to_linear_srgb(xyz);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(rgb[c], 1.0, 1e-3) << c;
}

TEST(ColorMatching, WeightsOfBinConstantLightEqualBinAverageFormula) {
  // A light that is constant inside bin i (box over the bin, scaled by E_i) has weights
  // E_i·∫_{bin} cmf dλ = E_i·Δλ_i·(bin average of cmf) in column i and zero elsewhere.
  const auto& cmf = cie1931();
  const auto bins = BinLayout::exponential(380, 780, 9, 1.2);
  for (int i = 0; i < bins.size(); ++i) {
    const double e_i = 0.5 + i;
    const Spectrum light = Spectrum({bins.lo_nm(i), bins.hi_nm(i)}, {1.0, 1.0}).scaled(e_i);
    const auto m = relight_weights(cmf, light, bins, LightUnits::Absolute);
    for (int c = 0; c < 3; ++c) {
      const double expected = e_i * bins.width_nm(i) * cmf.channel(c).bin_averages(bins)[i];
      EXPECT_NEAR(m(c, i), expected, 1e-12 * std::max(1.0, std::abs(expected))) << "bin " << i << " channel " << c;
      for (int j = 0; j < bins.size(); ++j) {
        if (j != i) {
          EXPECT_EQ(m(c, j), 0.0) << i << " " << j;
        }
      }
    }
  }
  // The same with a constant light over all bins (another code path: constant × table).
  const auto m = relight_weights(cmf, Spectrum::constant(2.5), bins, LightUnits::Absolute);
  for (int i = 0; i < bins.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(m(c, i), 2.5 * cmf.channel(c).integrate(bins.lo_nm(i), bins.hi_nm(i)), 1e-12) << i;
    }
  }
}

TEST(ColorMatching, BinsOfAnyLayoutSumToTheWholeIntegral) {
  const auto& cmf = cie1931();
  const Spectrum d65 = parse_spectrum("D65");
  for (const auto& bins : {BinLayout(), BinLayout::linear(380, 780, 37), BinLayout::exponential(380, 780, 20, 3.0),
                           BinLayout::exponential(380, 780, 20, -2.0),
                           BinLayout::from_edges({380, 381.3, 402.77, 499.5, 500, 650.25, 780})}) {
    const auto m = relight_weights(cmf, d65, bins, LightUnits::Absolute);
    for (int c = 0; c < 3; ++c) {
      const double whole = cmf.channel(c).integrate_product(d65, 380, 780);
      EXPECT_NEAR(m.row(c).sum(), whole, 1e-10 * whole) << bins.to_string() << " channel " << c;
    }
  }
}

TEST(ColorMatching, WeightsMatchBruteForceIntegration) {
  // A 1 nm tabulated light (blackbody, 300–900 nm) against a midpoint rule with 0.005 nm steps
  // (error ≈ h²/24·|(E·cmf)''|·Δλ, below 1e-7 relative here).
  const auto& cmf = cie1931();
  const Spectrum light = parse_spectrum("blackbody:4000K");
  const auto bins = BinLayout::from_edges({380, 402.5, 455.25, 530, 611.1, 700, 780});
  const auto m = relight_weights(cmf, light, bins, LightUnits::Absolute);
  for (int i = 0; i < bins.size(); ++i) {
    const int steps = static_cast<int>(bins.width_nm(i) / 0.005);
    for (int c = 0; c < 3; ++c) {
      const double brute = midpoint(light, cmf.channel(c), bins.lo_nm(i), bins.hi_nm(i), steps);
      EXPECT_NEAR(m(c, i), brute, 1e-6 * std::abs(brute) + 1e-12) << "bin " << i << " channel " << c;
    }
  }
}

TEST(ColorMatching, RelativeNormalisation) {
  const auto& cmf = cie1931();
  const Spectrum a = parse_spectrum("A");
  const auto rel = relight_weights(cmf, a, BinLayout(), LightUnits::RelativeToWhite);
  const auto abs = relight_weights(cmf, a, BinLayout(), LightUnits::Absolute);
  EXPECT_NEAR(rel.row(1).sum(), 1.0, 1e-12);
  EXPECT_NEAR((rel * abs.row(1).sum() - abs).norm(), 0.0, 1e-9 * abs.norm());
  // Scaling the light changes absolute weights, not relative ones.
  const auto rel2 = relight_weights(cmf, a.scaled(7.0), BinLayout(), LightUnits::RelativeToWhite);
  EXPECT_NEAR((rel2 - rel).norm(), 0.0, 1e-12);
}

TEST(ColorMatching, BinsOutsideTheTableWeighOnlyTheirInside) {
  // Default bins start at 380 nm; the 2012 tables start at 390 nm. Outside its table a CMF is zero, so
  // the first bin [380, 390+) weighs only its part above 390 nm and the white's Y is what the table
  // gives: the weights over 380–780 equal those over 390–780 with the first bins' inside parts.
  const auto& cmf = ColorMatching::get(Observer::Cie2012_2deg);
  const Spectrum d65 = parse_spectrum("D65");
  const auto w = relight_weights(cmf, d65, BinLayout::from_edges({380, 390, 400, 780}), LightUnits::Absolute);
  const auto inside = relight_weights(cmf, d65, BinLayout::from_edges({390, 400, 780}), LightUnits::Absolute);
  EXPECT_EQ(w.col(0).norm(), 0.0);  // [380, 390] lies wholly below the table
  EXPECT_NEAR((w.rightCols(2) - inside).norm(), 0.0, 1e-12 * inside.norm());
  EXPECT_NO_THROW((void)relight_weights(cmf, d65, BinLayout()));
  EXPECT_NE(cmf_coverage_note(cmf, BinLayout()).find("390"), std::string::npos);
  EXPECT_EQ(cmf_coverage_note(cmf, BinLayout::linear(390, 780, 10)), "");
  EXPECT_EQ(cmf_coverage_note(cie1931(), BinLayout()), "");
}

TEST(ColorMatching, RejectsDarkLights) {
  // No energy inside the bins.
  try {
    (void)relight_weights(cie1931(), parse_spectrum("box:790:820"), BinLayout());
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), "light");
    EXPECT_NE(std::string(e.what()).find("no energy"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)relight_weights(cie1931(), Spectrum(), BinLayout()), InputError);
  EXPECT_THROW((void)relight_weights(cie1931(), Spectrum::constant(0.0), BinLayout(), LightUnits::Absolute), InputError);
}
