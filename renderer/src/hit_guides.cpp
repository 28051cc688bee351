// The deterministic first-hit guide layers (hit_guides.h): one ray march per sub-pixel ray.
#include "prizma/render/hit_guides.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <utility>

#include "prizma/render/majorant_grid.h"
#include "prizma/render/path_tracer.h"
#include "prizma/spectral/colour_matching.h"

namespace prizma::render {
namespace {

constexpr int kFixed = 8;    // depth, normal x, y, z, albedo, density, albedo x, albedo z; then one per directional light
constexpr int kGrid = 2;     // kGrid² sub-pixel rays per pixel

// Per material: the reference extinction per unit density and the albedo's white-light luminance,
// both weighted by ȳ at the bins' centres (the luminance sees them so).
struct Reference {
  std::vector<double> sigma_t, albedo;
  std::vector<double> albedo_x, albedo_z;  // the albedo weighted by x̄ and z̄ (its chroma)
};

Reference reference(const Scene& scene) {
  const auto& cmf = spectral::ColorMatching::get(spectral::Observer::Cie1931_2deg);
  const auto& ybar = cmf.y();
  const spectral::BinLayout& bins = scene.settings.bins;
  std::vector<double> w(static_cast<std::size_t>(bins.size()));
  double total = 0.0;
  for (int i = 0; i < bins.size(); ++i) total += w[i] = std::max(0.0, ybar.eval(bins.centre_nm(i))) * (bins.hi_nm(i) - bins.lo_nm(i));
  if (!(total > 0.0)) {
    for (int i = 0; i < bins.size(); ++i) w[i] = bins.hi_nm(i) - bins.lo_nm(i);
    total = bins.max_nm() - bins.min_nm();
  }
  // x̄ and z̄ weights at the bins' centres, each normalised to sum 1 (plain average when 0 everywhere).
  std::vector<double> wx(w.size()), wz(w.size());
  double tx = 0.0, tz = 0.0;
  for (int i = 0; i < bins.size(); ++i) {
    const double width = bins.hi_nm(i) - bins.lo_nm(i);
    tx += wx[i] = std::max(0.0, cmf.x().eval(bins.centre_nm(i))) * width;
    tz += wz[i] = std::max(0.0, cmf.z().eval(bins.centre_nm(i))) * width;
  }
  for (int i = 0; i < bins.size(); ++i) {
    wx[i] = tx > 0.0 ? wx[i] / tx : 1.0 / bins.size();
    wz[i] = tz > 0.0 ? wz[i] / tz : 1.0 / bins.size();
  }
  Reference r;
  for (const Material& m : scene.medium.materials) {
    double s = 0.0, a = 0.0;
    for (int i = 0; i < bins.size(); ++i) {
      s += w[i] * m.sigma_t_per_unit.eval(bins.centre_nm(i));
      a += w[i] * m.albedo.eval(bins.centre_nm(i));
    }
    r.sigma_t.push_back(s / total);
    r.albedo.push_back(a / total);
    double ax = 0.0, az = 0.0;
    for (int i = 0; i < bins.size(); ++i) {
      ax += wx[i] * m.albedo.eval(bins.centre_nm(i));
      az += wz[i] * m.albedo.eval(bins.centre_nm(i));
    }
    r.albedo_x.push_back(ax);
    r.albedo_z.push_back(az);
  }
  return r;
}

struct Marcher {
  const Medium& medium;
  const PathTracer& tracer;
  const Reference& ref;
  double step, diagonal;
  Eigen::Vector3d voxel;

  // σt at p with the reference extinction (0 in empty space or outside the bounds).
  double sigma(const Eigen::Vector3d& p, std::uint16_t* material = nullptr) const {
    for (int a = 0; a < 3; ++a)
      if (p[a] < medium.bounds_min[a] || p[a] > medium.bounds_max[a]) return 0.0;
    std::uint16_t m = Medium::kEmpty;
    float d = 0.0f;
    tracer.lookup(p, m, d);
    if (material) *material = m;
    return m == Medium::kEmpty ? 0.0 : ref.sigma_t[m] * d;
  }

  // [t0, t1): the ray's span inside the bounds ({0, 0} when it misses them).
  std::pair<double, double> span(const Ray& ray) const {
    double t0 = 0.0, t1 = 0.0;
    if (!intersect_box(ray, medium.bounds_min, medium.bounds_max, t0, t1)) return {0.0, 0.0};
    return {t0, t1};
  }

  // The transmittance from p along the unit direction d to the bounds' edge (stops below e^−20).
  double transmittance(const Eigen::Vector3d& p, const Eigen::Vector3d& d) const {
    const auto [t0, t1] = span({p, d});
    double tau = 0.0;
    for (double t = t0; t < t1 && tau < 20.0; t += step) {
      const double len = std::min(step, t1 - t);
      tau += sigma(p + (t + 0.5 * len) * d) * len;
    }
    return std::exp(-tau);
  }

  // The planes of one ray (unit direction); `lights`: the unit directions toward the directional lights.
  std::vector<double> march(const Ray& ray, const std::vector<Eigen::Vector3d>& lights) const {
    std::vector<double> out(kFixed + lights.size(), 0.0);
    out[0] = 1.0;
    const auto [t0, t1] = span(ray);
    if (!(t0 < t1)) return out;
    double tau = 0.0;
    for (double t = t0; t < t1; t += step) {
      const double len = std::min(step, t1 - t);
      const double s = sigma(ray.origin + (t + 0.5 * len) * ray.direction);
      if (tau + s * len < 1.0) {
        tau += s * len;
        continue;
      }
      const double th = t + (1.0 - tau) / s;  // τ reaches 1 inside this step
      const Eigen::Vector3d p = ray.origin + th * ray.direction;
      out[0] = std::clamp((th - t0) / diagonal, 0.0, 1.0);
      Eigen::Vector3d grad;
      for (int a = 0; a < 3; ++a) {
        Eigen::Vector3d e = Eigen::Vector3d::Zero();
        e[a] = voxel[a];
        grad[a] = (sigma(p + e) - sigma(p - e)) / (2.0 * voxel[a]);
      }
      const double g = grad.norm();
      const Eigen::Vector3d n = g > 0.0 ? Eigen::Vector3d(-grad / g) : Eigen::Vector3d(-ray.direction);
      out[1] = n.x();
      out[2] = n.y();
      out[3] = n.z();
      std::uint16_t m = Medium::kEmpty;
      out[5] = sigma(p, &m) * diagonal;  // σt at the hit, per diagonal (unitless)
      if (m == Medium::kEmpty) sigma(ray.origin + (t + 0.5 * len) * ray.direction, &m);
      out[4] = m == Medium::kEmpty ? 0.0 : ref.albedo[m];
      out[6] = m == Medium::kEmpty ? 0.0 : ref.albedo_x[m];
      out[7] = m == Medium::kEmpty ? 0.0 : ref.albedo_z[m];
      for (std::size_t l = 0; l < lights.size(); ++l) out[kFixed + l] = transmittance(p, lights[l]);
      return out;
    }
    return out;
  }
};

bool directional(const Light& l) {
  return !l.emission && !l.is_point && !l.environment_map && l.direction.squaredNorm() > 0.0;
}

}  // namespace

std::vector<std::string> hit_guide_names(const Scene& scene) {
  std::vector<std::string> names = {"hit_depth", "hit_normal_x", "hit_normal_y", "hit_normal_z", "hit_albedo",
                                    "hit_density", "hit_albedo_x", "hit_albedo_z"};
  for (std::size_t l = 0; l < scene.lights.size(); ++l)
    if (directional(scene.lights[l])) names.push_back("hit_light" + std::to_string(l));
  return names;
}

std::vector<spectral::GuideLayer> hit_guides(const Scene& scene, const CameraModel& camera, const PathTracer& tracer) {
  const Medium& med = scene.medium;
  const Reference ref = reference(scene);
  Eigen::Vector3d voxel;
  for (int a = 0; a < 3; ++a) voxel[a] = (med.bounds_max[a] - med.bounds_min[a]) / std::max(1, med.dims[a]);
  const Marcher marcher{med, tracer, ref, 0.5 * voxel.minCoeff(), (med.bounds_max - med.bounds_min).norm(), voxel};
  const int w = camera.width(), h = camera.height();
  const std::size_t pixels = static_cast<std::size_t>(w) * h;
  std::vector<Eigen::Vector3d> lights;
  for (const Light& l : scene.lights)
    if (directional(l)) lights.push_back(l.direction.normalized());
  const std::vector<std::string> names = hit_guide_names(scene);
  const int planes = static_cast<int>(names.size());
  std::vector<spectral::GuideLayer> layers(planes);
  for (int k = 0; k < planes; ++k) {
    layers[k].name = names[k];
    layers[k].value.assign(pixels, 0.0f);
    layers[k].variance.assign(pixels, 0.0f);
  }
  constexpr int n = kGrid * kGrid;
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      std::array<std::vector<double>, n> v;
      for (int j = 0; j < n; ++j)
        v[j] = marcher.march(camera.generate(x + (j % kGrid + 0.5) / kGrid, y + (j / kGrid + 0.5) / kGrid), lights);
      const std::size_t p = static_cast<std::size_t>(y) * w + x;
      for (int k = 0; k < planes; ++k) {
        double mean = 0.0, sq = 0.0;
        for (int j = 0; j < n; ++j) mean += v[j][k];
        mean /= n;
        for (int j = 0; j < n; ++j) sq += (v[j][k] - mean) * (v[j][k] - mean);
        layers[k].value[p] = static_cast<float>(mean);
        layers[k].variance[p] = static_cast<float>(sq / (n * (n - 1)));  // the mean's, as the Monte Carlo guides'
      }
    }
  });
  return layers;
}

}  // namespace prizma::render
