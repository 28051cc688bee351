#pragma once
// Light design: a non-negative light spectrum under which two materials look the same (hide) or as
// different as possible (reveal), with the luminance of a reference light, optionally restricted to
// a non-negative mix of given primaries (LEDs, gaussians).
#include <vector>

#include "prizma/spectral/metamer_design.h"
#include "prizma/spectral/spectrum.h"

namespace prizma::spectral {

enum class LightGoal { Hide, Reveal };

struct LightDesignOptions {
  ColourSetting colour;
  // Free-form lights (no primaries): a non-negative combination of this many clamped cubic B-splines
  // over the bins' range, tabulated every `step_nm`. At least 6.
  int basis_size = 40;
  double step_nm = 5.0;
  // Radiant power limit: ∫E dλ over the bins at most this many times the reference light's at the
  // same luminance (0 = no limit). Without it a revealing light tends to put most of its power where
  // the eye barely sees (e.g. 700+ nm), which is valid but useless as a lamp.
  double max_power_ratio = 2.0;
  // Ascent iterations per start.
  int iterations = 150;
};

struct LightDesignResult {
  // The light, scaled so that ∫ light·ȳ dλ over the bins equals the reference light's.
  Spectrum light;
  // Mix weights of the primaries (free-form: of the basis functions), in the output's scale.
  std::vector<double> weights;
  double delta_e = 0.0;            // ΔE00 between the two albedos under the designed light
  double delta_e_reference = 0.0;  // … under the reference light
};

// Designs the light. `primaries` empty means free-form. Throws InputError naming "albedo-a",
// "albedo-b", "reference light" or "primaries[i]" for invalid spectra (negative light values, no
// energy in the bins), and "albedo-b" when the albedos have the same colour under every light (their
// difference cannot be revealed).
LightDesignResult design_light(const Spectrum& albedo_a, const Spectrum& albedo_b, LightGoal goal,
                               const Spectrum& reference_light, const std::vector<Spectrum>& primaries = {},
                               const LightDesignOptions& options = {});

}  // namespace prizma::spectral
