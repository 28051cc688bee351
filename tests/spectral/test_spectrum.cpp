// Spectrum: validation and exact integrals of piecewise-linear functions.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "prizma/spectral/error.h"
#include "prizma/spectral/spectrum.h"

using prizma::spectral::BinLayout;
using prizma::spectral::InputError;
using prizma::spectral::Spectrum;

TEST(Spectrum, TriangleIntegral) {
  // Triangle 0 → 1 → 0 over [400, 500]: area 50 exactly.
  const Spectrum tri({400, 450, 500}, {0, 1, 0});
  EXPECT_DOUBLE_EQ(tri.integrate(0, 1000), 50.0);
  EXPECT_DOUBLE_EQ(tri.integrate(400, 450), 25.0);
  // Partial: ∫_{425}^{475} = 50 − 2·(½·25·0.5) = 37.5
  EXPECT_DOUBLE_EQ(tri.integrate(425, 475), 37.5);
  EXPECT_DOUBLE_EQ(tri.eval(425), 0.5);
  EXPECT_DOUBLE_EQ(tri.eval(399), 0.0);
  EXPECT_DOUBLE_EQ(tri.eval(501), 0.0);
}
