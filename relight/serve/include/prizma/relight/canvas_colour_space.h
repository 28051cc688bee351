#pragma once
// Which colour space a browser's canvas must be told its pixels are in, for a display of the OCIO
// config: WebGL's drawingBufferColorSpace takes "srgb" and "display-p3" (CSS Color 4's predefined
// spaces a canvas may hold; Chromium has no Rec.2020 canvas), each with the sRGB curve.
#include <string>

#include "prizma/spectral/display.h"

namespace prizma::relight {

struct CanvasColourSpace {
  // "srgb", "display-p3", or empty when no canvas colour space shows the display's code values as
  // they are meant (other primaries or white, another curve, a transform that is not matrix + curve).
  std::string canvas;
  // What the display encodes, for the page to say: "BT.2020 primaries, D65 white, 2.4 power curve".
  std::string encoding;
};

// Found from the display's own transform (its primaries, white and curve, as the ICC profile of its
// PNGs: display_colour_space, output_image.h), never from its name; primaries and white match within
// 0.002 in xy.
CanvasColourSpace canvas_colour_space(const spectral::DisplayTransform& display, const std::string& name);

}  // namespace prizma::relight
