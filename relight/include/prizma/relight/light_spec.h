#pragma once
// LightSpec: one light layer's spectrum as the user gave it ("D65", "gaussian:550:5*2", "off").
#include <string>
#include <string_view>

#include "prizma/spectral/spectrum.h"
#include "prizma/spectral/spectrum_spec.h"

namespace prizma::relight {

struct LightSpec {
  std::string text = "D65";    // the spec as given, echoed into output metadata
  spectral::Spectrum spectrum;  // the spectrum without the trailing scale
  double scale = 1.0;          // trailing "*<factor>" factors, applied after normalisation
  bool off = false;            // "off": the layer contributes nothing
};

// Parses a light spec: "off", or any spectrum spec of spectral::parse_spectrum with optional
// trailing "*<factor>" scales (kept apart so that a light at scale k gives k times the image of the
// normalised light). Throws InputError naming ctx.input for bad specs or negative/non-finite scales.
LightSpec parse_light_spec(std::string_view text, const spectral::SpecContext& ctx = {});

}  // namespace prizma::relight
