// Colour matching functions, published chromaticities and exact relight weights.
#include <gtest/gtest.h>

#include "prizma/spectral/colour.h"
#include "prizma/spectral/colour_matching.h"
#include "prizma/spectral/error.h"

using namespace prizma::spectral;

TEST(ColorMatching, Cie1931Range) {
  const auto& cmf = ColorMatching::get(Observer::Cie1931_2deg);
  EXPECT_DOUBLE_EQ(cmf.lo_nm(), 360.0);
  EXPECT_DOUBLE_EQ(cmf.hi_nm(), 830.0);
  // CIE 1931 ȳ(555 nm) = 1.000000 (table value).
  EXPECT_NEAR(cmf.y().eval(555.0), 1.0, 1e-6);
  EXPECT_DOUBLE_EQ(ColorMatching::get(Observer::Cie2012_2deg).lo_nm(), 390.0);
}
