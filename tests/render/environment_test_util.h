#pragma once
// Shared by the environment-map tests: the solid-angle integral of a map's sampling density.
#include <cmath>
#include <numbers>

#include "prizma/render/environment_map.h"

namespace prizma::render::testing {

// ∫ pdf(ω) dω over the sphere by the midpoint rule in (θ, φ) on a 400 × 800 grid, finer than the
// maps' pixels: 1 within about 2e-3 for a density that is right.
inline double pdf_integral_over_sphere(const EnvironmentMap& map) {
  const int nt = 400, np = 800;
  double integral = 0.0;
  for (int i = 0; i < nt; ++i)
    for (int j = 0; j < np; ++j) {
      const double theta = std::numbers::pi * (i + 0.5) / nt, phi = 2.0 * std::numbers::pi * (j + 0.5) / np;
      const Eigen::Vector3d d(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      integral += map.pdf(d) * std::sin(theta) * (std::numbers::pi / nt) * (2.0 * std::numbers::pi / np);
    }
  return integral;
}

}  // namespace prizma::render::testing
