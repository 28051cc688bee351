#pragma once
// The colour of a reflectance under a light computed independently of the design and relight code,
// shared by the metamer- and light-design tests: the product spectra tabulated every 1 nm over
// 380–780 nm and integrated by ColorMatching (CIE 1931 2°), Lab relative to the light's white,
// CIEDE2000 from colour.h.
#include <Eigen/Core>
#include <vector>

#include "prizma/spectral/colour.h"
#include "prizma/spectral/colour_matching.h"
#include "prizma/spectral/spectrum.h"

namespace prizma::spectral::test {

// XYZ of `reflectance` under `light`: white-normalised (∫E·r·cmf / ∫E·ȳ), or the bare integral
// ∫E·r·cmf when `absolute`.
inline Eigen::Vector3d independent_xyz(const Spectrum& reflectance, const Spectrum& light, bool absolute = false) {
  std::vector<double> lambda, product, energy;
  for (int nm = 380; nm <= 780; ++nm) {
    lambda.push_back(nm);
    product.push_back(light.eval(nm) * reflectance.eval(nm));
    energy.push_back(light.eval(nm));
  }
  const ColorMatching& cmf = ColorMatching::get(Observer::Cie1931_2deg);
  const Eigen::Vector3d xyz = cmf.integrate(Spectrum(lambda, product));
  return absolute ? xyz : Eigen::Vector3d(xyz / cmf.integrate(Spectrum(lambda, energy)).y());
}

// CIEDE2000 between two reflectances under `light`, Lab relative to the light's white.
inline double independent_delta_e(const Spectrum& a, const Spectrum& b, const Spectrum& light) {
  const Eigen::Vector3d white = independent_xyz(Spectrum::constant(1.0), light);
  return delta_e2000(xyz_to_lab(independent_xyz(a, light), white), xyz_to_lab(independent_xyz(b, light), white));
}

}  // namespace prizma::spectral::test
