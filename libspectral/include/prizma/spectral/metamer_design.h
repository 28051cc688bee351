#pragma once
// Metamer design: a smooth reflectance in [0, 1] that has the same colour as a given one under one
// light ("match" light) and differs from it as much as possible under another ("split" light).
// Colours are computed the way the relighter computes them: XYZ = relight_weights(light, bins) ·
// bin averages of the reflectance, a perfect white at Y = 1, CIELAB relative to that white, CIEDE2000.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "prizma/spectral/bin_layout.h"
#include "prizma/spectral/colour_matching.h"
#include "prizma/spectral/spectrum.h"

namespace prizma::spectral {

// What every design computes colours with.
struct ColourSetting {
  Observer observer = Observer::Cie1931_2deg;
  // Bins of the colour computation. The default (1 nm over 380–780 nm) is the continuous integral to
  // within 1e-4; give a render's bins to design for what its relit image will show.
  BinLayout bins = BinLayout::linear(380.0, 780.0, 400);
};

// XYZ of a reflectance under a light, white-normalised (a perfect white has Y = 1). Throws InputError
// (input "light") when the light has no energy in the bins.
Eigen::Vector3d reflectance_xyz(const Spectrum& reflectance, const Spectrum& light, const ColourSetting& colour);
// CIEDE2000 between two reflectances under a light, in CIELAB relative to the light's white.
double delta_e2000_under(const Spectrum& a, const Spectrum& b, const Spectrum& light, const ColourSetting& colour);

// A light with the name it is reported under.
struct NamedLight {
  std::string name;
  Spectrum spectrum;
};
// The standard list every design reports: D65, A, F2, F11, LED-B3 (CIE 015:2018 tables in data/).
std::vector<NamedLight> standard_report_lights();

struct MetamerOptions {
  ColourSetting colour;
  // Smoothness: the reflectance is a combination of this many clamped cubic B-splines over the bins'
  // range (knot spacing (range)/(basis_size − 3)), tabulated every `step_nm`. At least 6.
  int basis_size = 20;
  double step_nm = 5.0;
  // Bounds of the reflectance (physically valid: within [0, 1]).
  double min_value = 0.0;
  double max_value = 1.0;
  // Search effort: Lab directions tried (up to 26) and ascent iterations per direction.
  int directions = 26;
  int iterations = 80;
  // The design fails (InputError) when no candidate differs by at least this ΔE00 under the split light.
  double min_split_delta_e = 0.5;
};

struct MetamerResult {
  // The metamer, tabulated every step_nm over the bins' range, values within [min_value, max_value].
  Spectrum reflectance;
  double delta_e_match = 0.0;  // ΔE00 to the input under the match light (≈ 0)
  double delta_e_split = 0.0;  // ΔE00 to the input under the split light (maximised)
};

// Designs the metamer. Throws InputError (input "albedo") when the albedo is outside [min, max] in the
// bins' range, "match light"/"split light" when a light has no energy, "options" for bad options,
// and "albedo" when no smooth metamer within the bounds matches it (e.g. a perfect white or black).
MetamerResult design_metamer(const Spectrum& albedo, const Spectrum& match_light, const Spectrum& split_light,
                             const MetamerOptions& options = {});

}  // namespace prizma::spectral
