// The canvas colour space of a display (canvas_colour_space.h).
#include "prizma/relight/canvas_colour_space.h"

#include <array>
#include <cmath>
#include <cstdio>

#include "prizma/spectral/output_image.h"

namespace prizma::relight {

namespace {

using Xy = std::array<double, 8>;  // red, green, blue, white: x, y each

// ITU-R BT.709 / IEC 61966-2-1, SMPTE EG 432-1 (P3-D65) and ITU-R BT.2020 primaries; the D65 white.
constexpr std::array<double, 6> kRec709 = {0.640, 0.330, 0.300, 0.600, 0.150, 0.060};
constexpr std::array<double, 6> kP3 = {0.680, 0.320, 0.265, 0.690, 0.150, 0.060};
constexpr std::array<double, 6> kRec2020 = {0.708, 0.292, 0.170, 0.797, 0.131, 0.046};
constexpr std::array<double, 2> kD65 = {0.3127, 0.3290};
constexpr double kXyTolerance = 0.002;

template <std::size_t N>
bool near(const Xy& xy, std::size_t first, const std::array<double, N>& want) {
  for (std::size_t i = 0; i < N; ++i)
    if (!(std::abs(xy[first + i] - want[i]) <= kXyTolerance)) return false;
  return true;
}

std::string xy_text(const Xy& xy, std::size_t i) {
  char text[40];
  std::snprintf(text, sizeof text, "(%.4f, %.4f)", xy[i], xy[i + 1]);
  return text;
}

}  // namespace

CanvasColourSpace canvas_colour_space(const spectral::DisplayTransform& display, const std::string& name) {
  const std::optional<spectral::PictureColourSpace> cs = display_colour_space(display, name);
  if (!cs) return {"", "a transform that is not a matrix and one curve"};
  const Xy& xy = cs->chromaticities;
  const bool rec709 = near(xy, 0, kRec709), p3 = near(xy, 0, kP3), rec2020 = near(xy, 0, kRec2020);
  const bool d65 = near(xy, 6, kD65);
  // The sRGB piecewise curve is what both canvas colour spaces use (display_colour_space writes it as
  // ICC parametric type 4 when the display's curve matches it).
  const bool srgb_curve = cs->curve_table.empty() && cs->curve_type == 4;
  CanvasColourSpace out;
  out.encoding = rec709    ? "Rec. 709 primaries"
                 : p3      ? "P3 primaries"
                 : rec2020 ? "BT.2020 primaries"
                           : "primaries " + xy_text(xy, 0) + " " + xy_text(xy, 2) + " " + xy_text(xy, 4);
  out.encoding += d65 ? ", D65 white" : ", white " + xy_text(xy, 6);
  if (!cs->curve_table.empty()) {
    out.encoding += ", a tabulated curve";
  } else if (srgb_curve) {
    out.encoding += ", sRGB curve";
  } else {
    char power[32];
    std::snprintf(power, sizeof power, ", %.1f power curve", cs->curve_parameters[0]);
    out.encoding += power;
  }
  if (d65 && srgb_curve && rec709) out.canvas = "srgb";
  if (d65 && srgb_curve && p3) out.canvas = "display-p3";
  return out;
}

}  // namespace prizma::relight
