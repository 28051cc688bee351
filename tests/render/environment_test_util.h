#pragma once
// Shared by the environment-map tests: the solid-angle integral of a map's sampling density.
#include <cmath>

#include "prizma/render/environment_map.h"

namespace prizma::render::testing {

// ∫ pdf(ω) dω over the sphere by the midpoint rule in (θ, φ) on a 400 × 800 grid, finer than the
// maps' pixels: 1 within about 2e-3 for a density that is right.
inline double pdf_integral_over_sphere(const EnvironmentMap& map) {
  constexpr double kPiLocal = 3.14159265358979323846;
  const int nt = 400, np = 800;
  double integral = 0.0;
  for (int i = 0; i < nt; ++i)
    for (int j = 0; j < np; ++j) {
      const double theta = kPiLocal * (i + 0.5) / nt, phi = 2.0 * kPiLocal * (j + 0.5) / np;
      const Eigen::Vector3d d(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      integral += map.pdf(d) * std::sin(theta) * (kPiLocal / nt) * (2.0 * kPiLocal / np);
    }
  return integral;
}

}  // namespace prizma::render::testing
