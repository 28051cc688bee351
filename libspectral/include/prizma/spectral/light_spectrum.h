#pragma once
// LightSpectrum: a light's spectrum as the user gave it ("D65", "gaussian:550:5*2", "off"), with the
// trailing scale kept apart from the spectrum so that normalisation applies to the bare spectrum
// and the scale after it (design.md: a light at scale 1 makes a perfect white Y = 1, so "D65*0.5"
// gives exactly half the image of "D65"). Shared by prizma-relight and prizma-render's preview.
#include <Eigen/Core>
#include <string>
#include <string_view>

#include "prizma/spectral/colour_matching.h"
#include "prizma/spectral/spectrum.h"
#include "prizma/spectral/spectrum_spec.h"

namespace prizma::spectral {

// The largest light scale (the product of a spec's trailing factors). Relighting multiplies it by the
// exposure (at most 2^64 ≈ 1.8e19) and the colour matching weights in float: below 1e12 the weights stay
// under 4e31, 10^7 short of float's largest, so a transport value up to that still gives a finite
// colour. "D65*1e39" gave weights of +inf, NaN pixels and a black image with exit 0.
constexpr double kMaxLightScale = 1e12;

struct LightSpectrum {
  std::string text = "D65";  // the spec as given, echoed into output metadata
  Spectrum spectrum;         // the spectrum without the trailing scale
  double scale = 1.0;        // trailing "*<factor>" factors, applied after normalisation
  bool off = false;          // "off" (or scale 0): the light contributes nothing
  bool scaled = false;       // the spec says its scale: trailing factors, or "off"
};

// Parses "off", or any parse_spectrum spec with optional trailing "*<factor>" scales. Throws
// InputError naming ctx.input for bad specs, negative / non-finite scales, or a scale (the factors'
// product) above kMaxLightScale.
LightSpectrum parse_light_spectrum(std::string_view text, const SpecContext& ctx = {});

// The product of the trailing "*<factor>" factors of a light spec (1 without any; 0 for "off"),
// without reading the spectrum itself. Throws InputError as parse_light_spectrum does for a bad factor.
double light_spec_scale(std::string_view text, const SpecContext& ctx = {});

// One spectrum given for every light at once (`--light F11`, a batch file's "lights": "F11", the
// shell's `light F11`, prizma.relight(lights="F11")) as light `current_scale` receives it: a spec
// that says its scale (trailing factors, "off") as it is; a bare one at the light's scale, so the
// scene's balance between its lights holds (a sky at "D65*0.2" becomes "F11*0.2") and a light that
// is off (scale 0) stays off. The text records the scale given ("F11*0.2"). docs/relight.md.
LightSpectrum at_light_scale(const LightSpectrum& given, double current_scale);

// relight_weights() of the bare spectrum times the scale; a zero matrix for a light that is off.
Eigen::Matrix<double, 3, Eigen::Dynamic> relight_weights(const ColorMatching& cmf, const LightSpectrum& light,
                                                          const BinLayout& bins,
                                                          LightUnits units = LightUnits::RelativeToWhite);

}  // namespace prizma::spectral
