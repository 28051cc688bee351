// Spectrum: validation and exact integrals of piecewise-linear functions against closed forms.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "prizma/spectral/error.h"
#include "prizma/spectral/spectrum.h"
#include "spectral/brute_force.h"

using prizma::spectral::BinLayout;
using prizma::spectral::InputError;
using prizma::spectral::Spectrum;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

void expect_invalid(std::vector<double> lam, std::vector<double> val, const std::string& needle) {
  try {
    (void)Spectrum(std::move(lam), std::move(val), "test.csv");
    ADD_FAILURE() << "no error, expected \"" << needle << "\"";
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), "test.csv");
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

// ∫ (u − 400)(u − 350)/10⁴ du, the antiderivative of the product of the two ramps used below.
double ramp_product_antiderivative(double u) { return (u * u * u / 3.0 - 375.0 * u * u + 140000.0 * u) / 1e4; }

using prizma::spectral::test_support::midpoint;

}  // namespace

TEST(Spectrum, TriangleIntegral) {
  // Triangle 0 → 1 → 0 over [400, 500]: area 50 exactly.
  const Spectrum tri({400, 450, 500}, {0, 1, 0});
  EXPECT_DOUBLE_EQ(tri.integrate(0, 1000), 50.0);
  EXPECT_DOUBLE_EQ(tri.integrate(400, 450), 25.0);
  // Partial, starting and ending between samples: 50 − 2·(½·25·0.5) = 37.5
  EXPECT_DOUBLE_EQ(tri.integrate(425, 475), 37.5);
  // Inside one segment: ∫_{410}^{420} (λ−400)/50 dλ = (20² − 10²)/100 = 3
  EXPECT_DOUBLE_EQ(tri.integrate(410, 420), 3.0);
  // Beyond the table on one side and entirely outside.
  EXPECT_DOUBLE_EQ(tri.integrate(475, 900), 0.5 * 25 * 0.5);
  EXPECT_DOUBLE_EQ(tri.integrate(600, 700), 0.0);
  EXPECT_DOUBLE_EQ(tri.integrate(100, 400), 0.0);
  // Reversed bounds give the negative; empty interval zero.
  EXPECT_DOUBLE_EQ(tri.integrate(475, 425), -37.5);
  EXPECT_DOUBLE_EQ(tri.integrate(430, 430), 0.0);
  EXPECT_DOUBLE_EQ(tri.eval(425), 0.5);
  EXPECT_DOUBLE_EQ(tri.eval(399), 0.0);
  EXPECT_DOUBLE_EQ(tri.eval(501), 0.0);
  EXPECT_DOUBLE_EQ(tri.eval(500), 0.0);
  EXPECT_DOUBLE_EQ(tri.eval(450), 1.0);
}

TEST(Spectrum, RampTimesRampOverPartialIntervals) {
  // f = (λ − 400)/100 on [400, 500]; g = (λ − 350)/100 on [350, 550], tabulated with extra,
  // unaligned breakpoints so the merged grid is irregular. Both are zero outside their tables.
  const Spectrum f({400, 437.3, 500}, {0, 0.373, 1});
  const Spectrum g({350, 410.5, 450, 550}, {0, 0.605, 1, 2});
  auto exact = [](double a, double b) { return ramp_product_antiderivative(b) - ramp_product_antiderivative(a); };
  EXPECT_NEAR(f.integrate_product(g, 420, 480), exact(420, 480), 1e-12);
  EXPECT_NEAR(f.integrate_product(g, 401.25, 433.75), exact(401.25, 433.75), 1e-12);
  // Beyond f's table: only [400, 500] contributes.
  EXPECT_NEAR(f.integrate_product(g, 300, 700), exact(400, 500), 1e-11);
  EXPECT_NEAR(g.integrate_product(f, 300, 700), exact(400, 500), 1e-11);
  EXPECT_NEAR(f.integrate_product(g, 460, 520), exact(460, 500), 1e-12);
  EXPECT_DOUBLE_EQ(f.integrate_product(g, 510, 540), 0.0);
  EXPECT_NEAR(f.integrate_product(g, 480, 420), -exact(420, 480), 1e-12);
}

TEST(Spectrum, ZeroOutsideTableAndConstants) {
  const Spectrum flat({400, 500}, {1, 1});
  const auto two = Spectrum::constant(2.0);
  EXPECT_TRUE(two.is_constant());
  EXPECT_DOUBLE_EQ(two.eval(-1e6), 2.0);
  EXPECT_DOUBLE_EQ(two.integrate(400, 410), 20.0);
  // The table jumps to zero at its ends: ∫_{300}^{600} 2·flat = 2·100.
  EXPECT_DOUBLE_EQ(flat.integrate_product(two, 300, 600), 200.0);
  EXPECT_DOUBLE_EQ(two.integrate_product(flat, 300, 600), 200.0);
  EXPECT_DOUBLE_EQ(two.integrate_product(Spectrum::constant(3.0), 10, 20), 60.0);
  EXPECT_DOUBLE_EQ(Spectrum().integrate(0, 1000), 0.0);
  EXPECT_DOUBLE_EQ(Spectrum().eval(500), 0.0);
  EXPECT_DOUBLE_EQ(flat.integrate_product(Spectrum(), 0, 1000), 0.0);
  EXPECT_DOUBLE_EQ(Spectrum::constant(0.0).integrate(-kInf, kInf), 0.0);
  EXPECT_DOUBLE_EQ(flat.integrate(-kInf, kInf), 100.0);
  EXPECT_EQ(two.domain_lo_nm(), -kInf);
  EXPECT_EQ(two.domain_hi_nm(), kInf);
  EXPECT_DOUBLE_EQ(flat.domain_lo_nm(), 400.0);
  EXPECT_DOUBLE_EQ(flat.domain_hi_nm(), 500.0);
  EXPECT_THROW((void)flat.integrate(kNaN, 500), InputError);
  EXPECT_THROW((void)Spectrum::constant(kNaN), InputError);
  EXPECT_THROW((void)Spectrum::constant(kInf), InputError);
}

TEST(Spectrum, ProductMatchesBruteForce) {
  // Two unrelated irregular tables; midpoint rule with 2·10⁵ steps has error ≈ h²/24·|f''| ≪ 1e-6.
  const Spectrum a({380, 391.7, 415, 470.2, 533, 610, 700}, {0.1, 0.9, 0.3, 1.7, 0.2, 0.8, 0.4});
  const Spectrum b({400, 402, 455.5, 456, 590, 720}, {2.0, 0.0, 1.0, 3.0, 0.5, 1.5});
  const double exact = a.integrate_product(b, 390, 690);
  // b is zero below 400 nm (outside its table); the brute force starts there so that the jump at
  // 400 nm falls on a step boundary instead of costing the midpoint rule an O(h) error.
  EXPECT_NEAR(exact, midpoint(a, b, 400, 690, 200000), 1e-6 * std::abs(exact));
  EXPECT_GT(exact, 100.0);
}

TEST(Spectrum, BinAveragesAreExact) {
  const Spectrum tri({400, 450, 500}, {0, 1, 0});
  const auto avg = tri.bin_averages(BinLayout::linear(400, 500, 4));
  ASSERT_EQ(avg.size(), 4u);
  EXPECT_DOUBLE_EQ(avg[0], 0.25);
  EXPECT_DOUBLE_EQ(avg[1], 0.75);
  EXPECT_DOUBLE_EQ(avg[2], 0.75);
  EXPECT_DOUBLE_EQ(avg[3], 0.25);
  // Bins partly outside the table average in the zeros.
  const auto wide = tri.bin_averages(BinLayout::linear(380, 520, 1));
  EXPECT_DOUBLE_EQ(wide[0], 50.0 / 140.0);
}

TEST(Spectrum, ResampledScaledMinMax) {
  const Spectrum tri({400, 450, 500}, {0, 1, 0});
  const Spectrum r = tri.resampled({400, 425, 450, 475, 500});
  EXPECT_EQ(r.values(), (std::vector<double>{0, 0.5, 1, 0.5, 0}));
  const Spectrum s = tri.scaled(3.0);
  EXPECT_DOUBLE_EQ(s.max_value(), 3.0);
  EXPECT_DOUBLE_EQ(s.min_value(), 0.0);
  EXPECT_DOUBLE_EQ(s.integrate(0, 1000), 150.0);
  EXPECT_DOUBLE_EQ(Spectrum::constant(2).scaled(0.5).eval(1), 1.0);
  EXPECT_THROW((void)tri.scaled(kNaN), InputError);
  EXPECT_THROW((void)Spectrum({400, 500}, {1e300, 1}).scaled(1e300), InputError);
  EXPECT_THROW((void)tri.resampled({500, 400}), InputError);
}

TEST(Spectrum, RejectsBadTables) {
  expect_invalid({400, 500, 450}, {1, 2, 3}, "strictly increasing: 450 nm follows 500 nm");
  expect_invalid({400, 500, 500}, {1, 2, 3}, "strictly increasing: 500 nm follows 500 nm");
  expect_invalid({400, kNaN}, {1, 2}, "wavelength is not a finite number");
  expect_invalid({400, kInf}, {1, 2}, "wavelength is not a finite number");
  expect_invalid({400, 500}, {1, kNaN}, "value at 500 nm is not a finite number");
  expect_invalid({400, 500}, {-kInf, 1}, "value at 400 nm is not a finite number");
  expect_invalid({400, 500}, {1}, "2 wavelengths but 1 values");
  expect_invalid({400}, {1}, "at least 2 samples");
  expect_invalid({}, {}, "at least 2 samples");
}
