#pragma once
// LightSampler: next-event estimation of one light with its own layer — directional (delta or
// cone), point, sphere, spot or environment map — at unit white (the spectrum is chosen when
// relighting). The tracer multiplies a sample's `value` by the phase function and the
// transmittance to `distance`; environment maps are also seen by paths that escape, weighted by
// multiple importance sampling against the phase function (docs/renderer.md, "Lights").
#include <Eigen/Core>
#include <memory>
#include <string>

#include "prizma/render/environment_map.h"
#include "prizma/render/rng.h"
#include "prizma/render/scene.h"

namespace prizma::render {

// One light sample seen from a point in the medium.
struct LightSample {
  Eigen::Vector3d direction{0, 0, 1};  // unit, from the point toward the light
  double distance = 0.0;               // to the light (infinity for directional and environment lights)
  double value = 0.0;                  // incident radiance / solid-angle density (irradiance for delta lights)
  double pdf = 0.0;                    // solid-angle density of `direction`, for MIS (0 = not MIS-weighted)
};

// pbrt-v4's spot profile (SpotLight::I): 1 inside the inner cone, 0 outside the outer one,
// smoothstep(cos_outer, cos_inner, cos θ) between (1 = cos_inner ≥ cos θ ≥ cos_outer = 0 edge:
// a hard edge when the two are equal).
double spot_falloff(double cos_theta, double cos_outer, double cos_inner);

// The power heuristic (Veach 1997, §9.2.3, β = 2): the weight of the technique of density a
// against the one of density b.
inline double power_heuristic(double a, double b) {
  if (!(a > 0.0)) return 0.0;
  const double a2 = a * a, b2 = b * b;
  return a2 / (a2 + b2);
}

// One line saying what a light is, for the render's log: "directional (x, y, z), angular size a°",
// "uniform environment", "point at (x, y, z)", "sphere of radius R at …", "spot at … axis … cone a°
// falloff b°", "environment map FILE (W×H, rotation r°, NEE + MIS)", "emission of the medium".
std::string describe_light(const Light& light);

class LightSampler {
 public:
  enum class Kind { Directional, Point, Sphere, Spot, Environment };

  // A light that is not the uniform environment nor the emission layer.
  explicit LightSampler(const Light& light);

  Kind kind() const { return m_kind; }
  // Draws a sample toward the light from p. False when the light sends nothing to p (outside a
  // spot's cone, inside a sphere light, at a point light's position, an environment map sampled
  // by the phase function only); then no random numbers beyond those drawn are needed.
  bool sample(const Eigen::Vector3d& p, Rng& rng, LightSample& out) const;

  // Environment maps: whether escaping paths see the map, and the radiance they see along `dir`
  // with the MIS weight against NEE for a path whose last direction had phase density
  // `phase_pdf` (0 for a camera ray: weight 1).
  bool seen_by_escapes() const { return m_kind == Kind::Environment; }
  double escape_radiance(const Eigen::Vector3d& dir, double phase_pdf) const;
  // True when NEE samples are MIS-weighted (environment maps with NEE).
  bool mis() const { return m_mis; }

 private:
  Kind m_kind = Kind::Directional;
  Eigen::Vector3d m_direction{0, 0, 1};  // directional: toward the light; spot: the axis
  double m_cos_max = 1.0;                // directional: cone half-angle cosine (1 = delta)
  Eigen::Vector3d m_position{0, 0, 0};
  double m_radius = 0.0;
  double m_cos_outer = -1.0, m_cos_inner = -1.0;  // spot
  std::shared_ptr<const EnvironmentMap> m_map;
  bool m_mis = false;
};

}  // namespace prizma::render
