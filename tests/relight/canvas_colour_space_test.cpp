// The canvas colour space of a display (canvas_colour_space.h), on the shipped OCIO config: found
// from each display's transform, sRGB is "srgb", Display P3 "display-p3" (both with the sRGB curve,
// what WebGL's drawingBufferColorSpace means by them), and Rec.2020 none: no canvas colour space holds
// BT.2020 primaries and a 2.4 power curve, and the page says so with this encoding text.
#include <gtest/gtest.h>

#include <string>

#include "prizma/relight/canvas_colour_space.h"

namespace prizma::relight {
namespace {

CanvasColourSpace of(const std::string& display) {
  spectral::DisplayOptions d;
  d.display = display;
  return canvas_colour_space(spectral::DisplayTransform(d), display);
}

TEST(CanvasColourSpace, SrgbAndDisplayP3HaveTheirCanvasSpaces) {
  const CanvasColourSpace srgb = of("sRGB");
  EXPECT_EQ(srgb.canvas, "srgb");
  EXPECT_EQ(srgb.encoding, "Rec. 709 primaries, D65 white, sRGB curve");
  const CanvasColourSpace p3 = of("Display P3");
  EXPECT_EQ(p3.canvas, "display-p3");
  EXPECT_EQ(p3.encoding, "P3 primaries, D65 white, sRGB curve");
}

TEST(CanvasColourSpace, Rec2020HasNone) {
  const CanvasColourSpace rec2020 = of("Rec.2020");
  EXPECT_EQ(rec2020.canvas, "");
  EXPECT_EQ(rec2020.encoding, "BT.2020 primaries, D65 white, 2.4 power curve");
}

}  // namespace
}  // namespace prizma::relight
