// LightSampler: next-event estimation of directional, point, sphere, spot and environment-map
// lights (docs/renderer.md, "Lights").
#include "prizma/render/light_sampler.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <limits>
#include <sstream>

#include "prizma/render/phase.h"

namespace prizma::render {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

double cos_deg(double deg) { return std::cos(deg * std::numbers::pi / 180.0); }

}  // namespace

double spot_falloff(double cos_theta, double cos_outer, double cos_inner) {
  if (cos_theta >= cos_inner) return 1.0;
  if (cos_theta <= cos_outer) return 0.0;
  const double t = (cos_theta - cos_outer) / (cos_inner - cos_outer);
  return t * t * (3.0 - 2.0 * t);
}

LightSampler::LightSampler(const Light& light) {
  if (light.environment_map) {
    m_kind = Kind::Environment;
    m_map = light.environment_map;
    using S = Light::EnvironmentSampling;
    m_mis = light.environment_sampling == S::Mis ||
            (light.environment_sampling == S::Auto && !m_map->is_constant());
  } else if (light.is_point) {
    m_position = light.position;
    m_radius = light.radius;
    m_kind = light.radius > 0.0 ? Kind::Sphere : Kind::Point;
    if (light.spot_direction.squaredNorm() > 0.0) {
      m_kind = Kind::Spot;
      m_direction = light.spot_direction.normalized();
      m_cos_outer = cos_deg(light.spot_cone_deg);
      m_cos_inner = cos_deg(std::max(0.0, light.spot_cone_deg - light.spot_falloff_deg));
    }
  } else {
    m_kind = Kind::Directional;
    m_direction = light.direction.normalized();
    m_cos_max = light.angular_size_deg > 0 ? cos_deg(0.5 * light.angular_size_deg) : 1.0;
  }
}

bool LightSampler::sample(const Eigen::Vector3d& p, Rng& rng, LightSample& out) const {
  out.pdf = 0.0;
  switch (m_kind) {
    case Kind::Directional: {
      // Delta, or uniform in the cone with radiance 1/Ω: either way irradiance 1, value 1.
      out.direction = m_direction;
      if (m_cos_max < 1.0) {
        const double cos_t = 1.0 - rng.uniform_double() * (1.0 - m_cos_max);
        out.direction = direction_around(m_direction, cos_t, rng.uniform_double());
      }
      out.distance = kInfinity;
      out.value = 1.0;
      return true;
    }
    case Kind::Point:
    case Kind::Spot: {
      // Intensity I(ω) = 1 (point) or the spot profile, inverse-square: irradiance I / r².
      const Eigen::Vector3d to = m_position - p;
      const double r2 = to.squaredNorm();
      if (!(r2 > 0.0)) return false;
      const double r = std::sqrt(r2);
      out.direction = to / r;
      out.distance = r;
      double intensity = 1.0;
      if (m_kind == Kind::Spot) intensity = spot_falloff(-out.direction.dot(m_direction), m_cos_outer, m_cos_inner);
      if (!(intensity > 0.0)) return false;
      out.value = intensity / r2;
      return true;
    }
    case Kind::Sphere: {
      // A sphere of radius R emitting radiance L = 1/(πR²) outward (intensity πR²·L = 1 in every
      // direction, power 4π as the point light's), sampled uniformly in the cone it subtends
      // (pbrt-v4, Sphere::Sample by solid angle): pdf 1/(2π(1 − cos θmax)), value L/pdf =
      // 2(1 − cos θmax)/R² = 2/(d²(1 + cos θmax)), computed in the second form: R² drops out, so a
      // radius of 1e-200 (R² underflows to 0, and L overflows) is the point light it tends to, not NaN.
      const Eigen::Vector3d to = m_position - p;
      const double d2 = to.squaredNorm(), r2 = m_radius * m_radius;
      if (!(d2 > r2)) return false;  // inside the sphere: its surface emits outward only
      const double d = std::sqrt(d2);
      const double sin2_max = r2 / d2;
      const double cos_max = std::sqrt(std::max(0.0, 1.0 - sin2_max));
      const double one_minus_cos = sin2_max / (1.0 + cos_max);  // 1 − cos θmax without cancellation
      const double cos_t = 1.0 - rng.uniform_double() * one_minus_cos;
      out.direction = direction_around(to / d, cos_t, rng.uniform_double());
      const double b = d * cos_t;
      const double perp2 = std::max(0.0, d2 - b * b);
      out.distance = std::max(0.0, b - std::sqrt(std::max(0.0, r2 - perp2)));
      out.value = 2.0 / (d2 * (1.0 + cos_max));
      return true;
    }
    case Kind::Environment: {
      if (!m_mis) return false;  // phase sampling alone: the map is seen only by escaping paths
      const double u0 = rng.uniform_double(), u1 = rng.uniform_double();
      double radiance = 0.0;
      const double pdf = m_map->sample(u0, u1, out.direction, radiance);
      if (!(pdf > 0.0) || !(radiance > 0.0)) return false;
      out.distance = kInfinity;
      out.value = radiance / pdf;
      out.pdf = pdf;
      return true;
    }
  }
  return false;
}

std::string describe_light(const Light& l) {
  std::ostringstream o;
  o.precision(6);
  auto vec = [&](const Eigen::Vector3d& v) { o << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")"; };
  if (l.emission) {
    o << "emission of the medium";
  } else if (l.environment_map) {
    const EnvironmentMap& m = *l.environment_map;
    o << "environment map " << l.environment_file << " (" << m.width() << "×" << m.height() << ", rotation "
      << l.rotation_deg << "°, " << (LightSampler(l).mis() ? "NEE + MIS" : "constant: phase sampling") << ")";
  } else if (l.is_point) {
    if (l.spot_direction.squaredNorm() > 0.0) {
      o << "spot at ";
      vec(l.position);
      o << " axis ";
      vec(l.spot_direction);
      o << " cone " << l.spot_cone_deg << "° falloff " << l.spot_falloff_deg << "°";
    } else {
      o << (l.radius > 0.0 ? "sphere" : "point");
      if (l.radius > 0.0) o << " of radius " << l.radius;
      o << " at ";
      vec(l.position);
    }
  } else if (l.direction.squaredNorm() == 0.0) {
    o << "uniform environment";
  } else {
    o << "directional ";
    vec(l.direction);
    o << ", angular size " << l.angular_size_deg << "°";
  }
  return o.str();
}

double LightSampler::escape_radiance(const Eigen::Vector3d& dir, double phase_pdf) const {
  if (m_kind != Kind::Environment) return 0.0;
  const double radiance = m_map->radiance(dir);
  if (!m_mis || !(phase_pdf > 0.0) || !(radiance > 0.0)) return radiance;
  return radiance * power_heuristic(phase_pdf, m_map->pdf(dir));
}

}  // namespace prizma::render
