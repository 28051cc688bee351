#pragma once
// LightSpec: one light layer's spectrum as the user gave it. The parser lives in libspectral
// (light_spectrum.h) so that prizma-render's preview reads light specs exactly as the relighter does.
#include "prizma/spectral/light_spectrum.h"

namespace prizma::relight {

using LightSpec = spectral::LightSpectrum;

inline LightSpec parse_light_spec(std::string_view text, const spectral::SpecContext& ctx = {}) {
  return spectral::parse_light_spectrum(text, ctx);
}

}  // namespace prizma::relight
