#pragma once
// Henyey–Greenstein phase function. Convention: cos_theta is the cosine between the propagation
// direction before and after scattering (g > 0 forward scattering), p integrates to 1 over the
// sphere. Sampling uses the inversion of pbrt-v4 (Pharr, Jakob, Humphreys, 4th ed., §11.3.1),
// which stays finite and accurate as |g| → 1; |g| < 1e-3 is sampled as isotropic.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace prizma::render {

constexpr double kInv4Pi = 1.0 / (4.0 * std::numbers::pi);

// p_HG(cos θ; g) = (1 − g²) / (4π (1 + g² − 2g cos θ)^{3/2}), per steradian.
inline float hg_phase(float cos_theta, float g) {
  const float denom = 1.0f + g * g - 2.0f * g * cos_theta;
  return static_cast<float>(kInv4Pi) * (1.0f - g * g) / (denom * std::sqrt(std::max(denom, 1e-12f)));
}

// cos θ distributed as p_HG(·; g), from u in (0, 1).
inline float hg_sample_cos(float g, float u) {
  if (std::abs(g) < 1e-3f) return 1.0f - 2.0f * u;
  const float s = (1.0f - g * g) / (1.0f - g + 2.0f * g * u);
  const float c = (1.0f + g * g - s * s) / (2.0f * g);
  return std::clamp(c, -1.0f, 1.0f);
}

// An orthonormal basis around unit w (Duff et al., "Building an orthonormal basis, revisited", 2017).
inline void orthonormal_basis(const Eigen::Vector3d& w, Eigen::Vector3d& a, Eigen::Vector3d& b) {
  const double sign = std::copysign(1.0, w.z());
  const double p = -1.0 / (sign + w.z());
  const double q = w.x() * w.y() * p;
  a = Eigen::Vector3d(1.0 + sign * w.x() * w.x() * p, sign * q, -sign * w.x());
  b = Eigen::Vector3d(q, sign + w.y() * w.y() * p, -w.y());
}

// The unit direction at angle acos(cos_theta) from unit w, azimuth 2π·u_phi.
inline Eigen::Vector3d direction_around(const Eigen::Vector3d& w, double cos_theta, double u_phi) {
  Eigen::Vector3d a, b;
  orthonormal_basis(w, a, b);
  const double sin_theta = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
  const double phi = 2.0 * std::numbers::pi * u_phi;
  return (sin_theta * std::cos(phi)) * a + (sin_theta * std::sin(phi)) * b + cos_theta * w;
}

}  // namespace prizma::render
