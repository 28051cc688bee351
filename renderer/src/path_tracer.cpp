#include "prizma/render/path_tracer.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "prizma/render/fluorescence.h"
#include "prizma/render/phase.h"
#include "prizma/spectral/error.h"

namespace prizma::render {
namespace {

// Ratio tracking's Russian roulette: below this largest transmittance, stop with probability kRrStop.
constexpr float kTransmittanceRrThreshold = 0.05f;
constexpr float kTransmittanceRrStop = 0.75f;
// Tracking steps (collisions + shadow steps) one path may take. The scene loader bounds the
// extinction so that a crossing takes at most ~2·10^6 steps; a path beyond this bound (albedo 1
// in a very dense medium) is abandoned as NaN, which the render counts and reports, so every path
// ends in bounded time.
constexpr std::int64_t kMaxPathSteps = std::int64_t{1} << 28;
constexpr float kAbandoned = std::numeric_limits<float>::quiet_NaN();
constexpr double kFloatMax = std::numeric_limits<float>::max();

// Lanes known at compile time (1) or not (0 = scratch.lanes).
template <int kLanes>
int lane_count(const PathScratch& s) {
  return kLanes > 0 ? kLanes : s.lanes;
}

}  // namespace

double spectrum_max_over(const spectral::Spectrum& s, double lo_nm, double hi_nm) {
  double m = std::max(s.eval(lo_nm), s.eval(hi_nm));
  for (std::size_t k = 0; k < s.wavelengths_nm().size(); ++k) {
    const double l = s.wavelengths_nm()[k];
    if (l >= lo_nm && l <= hi_nm) m = std::max(m, s.values()[k]);
  }
  return m;
}

PathTracer::PathTracer(const Scene& scene, double lambda_lo_nm, double lambda_hi_nm, bool use_grid)
    : m_medium(&scene.medium), m_max_bounces(scene.settings.max_bounces) {
  for (const MaterialEvents& e : choose_event_probabilities(scene.settings.event_probabilities, scene.medium.materials,
                                                            scene.settings.bins))
    m_events.push_back(e.scheme);
  const Medium& med = scene.medium;
  if (med.dims[0] < 1 || med.dims[1] < 1 || med.dims[2] < 1 || med.material.size() != med.voxel_count() ||
      med.density.size() != med.voxel_count())
    throw spectral::InputError("medium", "voxel arrays do not match dims");
  m_trilinear = med.interpolation == Interpolation::Trilinear;
  if (m_trilinear) {
    if (med.value.size() != med.voxel_count())
      throw spectral::InputError("medium", "trilinear interpolation needs one value per voxel");
    for (const MaterialRule& r : med.rules)
      if (r.material < 0 || static_cast<std::size_t>(r.material) >= med.materials.size())
        throw spectral::InputError("medium", "rule names material " + std::to_string(r.material) + ", which does not exist");
  }
  for (int a = 0; a < 3; ++a) {
    const double extent = med.bounds_max[a] - med.bounds_min[a];
    if (!(extent > 0)) throw spectral::InputError("medium", "bounds must have positive extent");
    m_inv_voxel[a] = med.dims[a] / extent;
  }
  std::vector<float> sigma_t_max(med.materials.size());
  m_wavelength_independent = true;
  for (std::size_t m = 0; m < med.materials.size(); ++m) {
    const Material& mat = med.materials[m];
    // Round the bound up by one float ulp so that σt at any wavelength never exceeds it.
    double smax = spectrum_max_over(mat.sigma_t_per_unit, lambda_lo_nm, lambda_hi_nm);
    if (mat.fluorescent) smax += spectrum_max_over(mat.fluorescence.absorption, lambda_lo_nm, lambda_hi_nm);  // σt + σf
    sigma_t_max[m] = std::nextafter(static_cast<float>(std::max(0.0, smax)), 1e30f);
    m_g_constant.push_back(mat.anisotropy.is_constant() ? 1 : 0);
    const bool emits = mat.emission.max_value() > 0.0;
    m_emits.push_back(emits ? 1 : 0);
    m_any_emission = m_any_emission || emits;
    const bool fl = mat.fluorescent && mat.fluorescence.quantum_yield > 0.0;
    m_fluorescent.push_back(fl ? 1 : 0);
    m_any_fluorescence = m_any_fluorescence || fl;
    m_fl_emission.push_back(spectral::Spectrum::constant(0.0));
    if (fl) {
      const double area = fluorescence_emission_area(mat.fluorescence.emission);
      if (!(area > 0.0) || !std::isfinite(area) || !(mat.fluorescence.quantum_yield <= 1.0))
        throw spectral::InputError("medium", "material \"" + mat.name + "\": fluorescence needs an emission of positive area and q in [0, 1]");
      m_fl_emission.back() = mat.fluorescence.emission.scaled(1.0 / area);
    }
    if (mat.fluorescent) m_wavelength_independent = false;
    if (!mat.albedo.is_constant() || !mat.sigma_t_per_unit.is_constant() || !mat.anisotropy.is_constant() ||
        !mat.emission.is_constant())
      m_wavelength_independent = false;
  }
  for (std::size_t v = 0; v < med.voxel_count(); ++v)
    if (med.material[v] != Medium::kEmpty && med.material[v] >= med.materials.size())
      throw spectral::InputError("medium", "voxel material index " + std::to_string(med.material[v]) +
                                               " out of range");
  m_grid = MajorantGrid(med, sigma_t_max, use_grid ? MajorantGrid::kCellVoxels : 0);
  for (std::size_t l = 0; l < scene.lights.size(); ++l) {
    const Light& light = scene.lights[l];
    if (light.emission) {
      if (m_emission_light >= 0) throw spectral::InputError("lights", "more than one emission light");
      m_emission_light = static_cast<int>(l);
      continue;
    }
    if (light.direction.squaredNorm() == 0.0 && !light.is_point && !light.environment_map) continue;
    m_lights.emplace_back(light);
    if (m_lights.back().seen_by_escapes()) m_escape_lights.push_back(static_cast<int>(m_lights.size()) - 1);
    m_any_mis = m_any_mis || m_lights.back().mis();
    m_directional_index.push_back(static_cast<int>(l));
  }
  if (m_any_emission && m_emission_light < 0)
    throw spectral::InputError("lights", "a material emits but the scene has no emission light");
}

void PathTracer::prepare(PathScratch& s, int lanes) const {
  const std::size_t n = static_cast<std::size_t>(lanes);
  const std::size_t nm = m_medium->materials.size();
  s.lanes = lanes;
  s.lambda_nm.assign(n, 0.0f);
  s.sigma_t.assign(nm * n, 0.0f);
  s.albedo.assign(nm * n, 0.0f);
  s.g.assign(nm * n, 0.0f);
  s.emission_le.assign(nm * n, 0.0f);
  s.material_stamp.assign(nm, 0);
  s.path_id = 0;
  for (auto* v : {&s.weight, &s.transmittance, &s.phase, &s.sigma_a, &s.sigma_s, &s.sigma_n, &s.environment, &s.emission})
    v->assign(n, 0.0f);
  s.directional.assign(m_lights.size() * n, 0.0f);
  s.width_nm.assign(n, 0.0f);
  s.lo_nm.assign(n, 0.0f);
  s.fl_active = false;
  const bool any_fluorescent = std::any_of(m_medium->materials.begin(), m_medium->materials.end(),
                                           [](const Material& m) { return m.fluorescent; });
  if (any_fluorescent) {
    s.fl_out.assign(nm * n, 0.0f);
    s.fl_in.assign(nm * n, 0.0f);
    s.fl_lambda_sum.assign(nm, 0.0);
    for (auto* v : {&s.zero_g, &s.fl_a, &s.fl_environment, &s.fl_emission}) v->assign(n, 0.0f);
    s.fl_directional.assign(m_lights.size() * n, 0.0f);
  }
}

bool PathTracer::hits_medium(const Ray& ray) const {
  double t0, t1;
  return intersect_box(ray, m_medium->bounds_min, m_medium->bounds_max, t0, t1);
}

void PathTracer::evaluate_material(int m, PathScratch& s) const {
  // Once per path and material: the spectra at the path's wavelengths, so that a collision costs a
  // voxel lookup and a few multiplies.
  const Material& mat = m_medium->materials[m];
  const int n = s.lanes;
  float* st = s.sigma_t.data() + static_cast<std::size_t>(m) * n;
  float* al = s.albedo.data() + static_cast<std::size_t>(m) * n;
  float* g = s.g.data() + static_cast<std::size_t>(m) * n;
  float* le = s.emission_le.data() + static_cast<std::size_t>(m) * n;
  for (int i = 0; i < n; ++i) {
    const double l = s.lambda_nm[i];
    st[i] = static_cast<float>(std::max(0.0, mat.sigma_t_per_unit.eval(l)));
    al[i] = static_cast<float>(std::clamp(mat.albedo.eval(l), 0.0, 1.0));
    g[i] = static_cast<float>(std::clamp(mat.anisotropy.eval(l), -0.9999, 0.9999));
    if (m_emits[m]) le[i] = static_cast<float>(std::max(0.0, mat.emission.eval(l)));
  }
  if (mat.fluorescent) evaluate_fluorescence(m, s);
  s.material_stamp[m] = s.path_id;
}

void PathTracer::evaluate_fluorescence(int m, PathScratch& s) const {
  // σf joins the extinction (the albedo rescaled so that σs stays albedo·σt), and the two sides of
  // the event. Energy radiance: a photon absorbed at λin carries hc/λin, one re-emitted at λout
  // hc/λout, so the source at λout is q·ρ(λout)·∫ σf(λin)·(λin/λout)·L̄(λin) dλin (ρ the normalised
  // emission, L̄ the radiance averaged over directions). Over the path's jittered lanes
  // ∫ σf·λ·L̄ dλ ≈ Σ_j Δj·σf(λj)·λj·L̄(λj) (unbiased per bin), so the source at lane i is
  // Φ_i·Σ_j p_j·L̄(λj) with Φ_i = q·ρ(λi)/λi·Λ, p_j = Δj·σf(λj)·λj/Λ and Λ = Σ_j Δj·σf(λj)·λj.
  const Material& mat = m_medium->materials[m];
  const int n = s.lanes;
  float* st = s.sigma_t.data() + static_cast<std::size_t>(m) * n;
  float* al = s.albedo.data() + static_cast<std::size_t>(m) * n;
  float* fo = s.fl_out.data() + static_cast<std::size_t>(m) * n;
  float* fi = s.fl_in.data() + static_cast<std::size_t>(m) * n;
  double big_lambda = 0.0;
  for (int i = 0; i < n; ++i) {
    const double l = s.lambda_nm[i];
    const auto sf = static_cast<float>(std::max(0.0, mat.fluorescence.absorption.eval(l)));
    const float st0 = st[i];
    st[i] = st0 + sf;
    al[i] = st[i] > 0.0f ? al[i] * (st0 / st[i]) : 0.0f;
    fi[i] = static_cast<float>(static_cast<double>(s.width_nm[i]) * sf * l);
    big_lambda += fi[i];
  }
  s.fl_lambda_sum[m] = big_lambda;
  if (!m_fluorescent[m] || !(big_lambda > 0.0)) {
    std::fill(fo, fo + n, 0.0f);
    std::fill(fi, fi + n, 0.0f);
    return;
  }
  const double q = mat.fluorescence.quantum_yield;
  for (int i = 0; i < n; ++i) {
    const double l = s.lambda_nm[i];
    fo[i] = static_cast<float>(q * std::max(0.0, m_fl_emission[m].eval(l)) / l * big_lambda);
    fi[i] = static_cast<float>(fi[i] / big_lambda);
  }
}

void PathTracer::lookup(const Eigen::Vector3d& p, std::uint16_t& material, float& density) const {
  const Medium& med = *m_medium;
  if (!med.clip.empty() && med.clipped(p)) {  // cut away: empty, so a null collision (unbiased)
    material = Medium::kEmpty;
    density = 0.0f;
    return;
  }
  if (m_trilinear) {
    classify(interpolate(p), material, density);
    return;
  }
  int idx[3];
  for (int a = 0; a < 3; ++a)
    idx[a] = std::clamp(static_cast<int>((p[a] - med.bounds_min[a]) * m_inv_voxel[a]), 0, med.dims[a] - 1);
  const std::size_t v = (static_cast<std::size_t>(idx[2]) * med.dims[1] + idx[1]) * med.dims[0] + idx[0];
  material = med.material[v];
  density = med.density[v];
}

float PathTracer::interpolate(const Eigen::Vector3d& p) const {
  // Trilinear between voxel centres (voxel i's centre at continuous coordinate i + 0.5), clamped to
  // the edge voxels within half a voxel of the box's faces. A point whose eight voxels include a
  // non-finite value is empty (NaN). The result is clamped to the eight values' range so that the
  // majorant grid's bound over that range holds exactly, float rounding included.
  const Medium& med = *m_medium;
  int i0[3], i1[3];
  float f[3];
  for (int a = 0; a < 3; ++a) {
    const double x = (p[a] - med.bounds_min[a]) * m_inv_voxel[a] - 0.5;
    const double fl = std::floor(x);
    f[a] = static_cast<float>(x - fl);
    const int i = static_cast<int>(fl);
    i0[a] = std::clamp(i, 0, med.dims[a] - 1);
    i1[a] = std::clamp(i + 1, 0, med.dims[a] - 1);
  }
  const std::size_t nx = static_cast<std::size_t>(med.dims[0]), nxy = nx * med.dims[1];
  const float* v = med.value.data();
  auto at = [&](int x, int y, int z) { return v[static_cast<std::size_t>(z) * nxy + static_cast<std::size_t>(y) * nx + x]; };
  const float c000 = at(i0[0], i0[1], i0[2]), c100 = at(i1[0], i0[1], i0[2]);
  const float c010 = at(i0[0], i1[1], i0[2]), c110 = at(i1[0], i1[1], i0[2]);
  const float c001 = at(i0[0], i0[1], i1[2]), c101 = at(i1[0], i0[1], i1[2]);
  const float c011 = at(i0[0], i1[1], i1[2]), c111 = at(i1[0], i1[1], i1[2]);
  const float lo = std::min({c000, c100, c010, c110, c001, c101, c011, c111});
  const float hi = std::max({c000, c100, c010, c110, c001, c101, c011, c111});
  if (!std::isfinite(lo) || !std::isfinite(hi) ||
      !std::isfinite(c000 + c100 + c010 + c110 + c001 + c101 + c011 + c111))
    return std::numeric_limits<float>::quiet_NaN();
  const float x00 = c000 + f[0] * (c100 - c000), x10 = c010 + f[0] * (c110 - c010);
  const float x01 = c001 + f[0] * (c101 - c001), x11 = c011 + f[0] * (c111 - c011);
  const float y0 = x00 + f[1] * (x10 - x00), y1 = x01 + f[1] * (x11 - x01);
  return std::clamp(y0 + f[2] * (y1 - y0), lo, hi);
}

void PathTracer::classify(float value, std::uint16_t& material, float& density) const {
  // Post-classification, exactly as build_medium classifies a voxel: the first rule whose range
  // holds the value, its density ramp at the value; empty when none matches or the density is 0.
  material = Medium::kEmpty;
  density = 0.0f;
  if (!std::isfinite(value)) return;
  const double v = value;
  for (const MaterialRule& r : m_medium->rules) {
    if (v >= r.value_lo && v <= r.value_hi) {
      const auto d = static_cast<float>(r.density.eval(v));
      if (d > 0.0f) {
        material = static_cast<std::uint16_t>(r.material);
        density = d;
      }
      return;
    }
  }
}

void PathTracer::trace(const Ray& ray, Rng& rng, PathScratch& s) const {
  if (s.lanes == 1)
    trace_lanes<1>(ray, rng, s);
  else
    trace_lanes<0>(ray, rng, s);
}

void PathTracer::add_escape(const Eigen::Vector3d& dir, double phase_pdf, const float* w, float* lights_out,
                            PathScratch& s) const {
  const int n = s.lanes;
  for (int k : m_escape_lights) {
    const auto radiance = static_cast<float>(m_lights[k].escape_radiance(dir, phase_pdf));
    if (!(radiance > 0.0f)) continue;
    float* __restrict out = lights_out + static_cast<std::size_t>(k) * n;
    for (int i = 0; i < n; ++i) out[i] += w[i] * radiance;
  }
}

template <int kLanes>
void PathTracer::transmittance(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, Rng& rng,
                               PathScratch& s, double t_max) const {
  // Ratio tracking (Novák, Selle, Jarosz 2014) against the cell majorants, every lane at once:
  // T *= 1 − σt/μ̄ at each tentative collision, with Russian roulette once T is small.
  const int n = lane_count<kLanes>(s);
  float* __restrict T = s.transmittance.data();
  for (int i = 0; i < n; ++i) T[i] = 1.0f;
  const Ray ray{origin, dir};
  double t_enter, t_exit;
  if (!intersect_box(ray, m_medium->bounds_min, m_medium->bounds_max, t_enter, t_exit)) return;
  t_exit = std::min(t_exit, t_max);  // a light inside or before the box: only the medium up to it
  if (!(t_exit > t_enter)) return;
  MajorantTraversal walk(m_grid, ray, t_enter, t_exit);
  MajorantTraversal::Segment seg;
  const std::int64_t step_limit = s.counters.shadow_steps + kMaxPathSteps;
  while (walk.next(seg)) {
    ++s.counters.majorant_cells;
    if (seg.majorant <= 0.0f) continue;
    const float inv_mu = 1.0f / seg.majorant;
    double t = seg.t0;
    for (;;) {
      t -= std::log(rng.uniform()) * inv_mu;
      if (t >= seg.t1) break;
      if (++s.counters.shadow_steps > step_limit) {
        for (int i = 0; i < n; ++i) T[i] = kAbandoned;
        return;
      }
      std::uint16_t m;
      float d;
      lookup(origin + t * dir, m, d);
      if (m == Medium::kEmpty || d <= 0.0f) continue;
      if (s.material_stamp[m] != s.path_id) evaluate_material(m, s);
      const float* __restrict st = s.sigma_t.data() + static_cast<std::size_t>(m) * n;
      const float scale = d * inv_mu;
      float tmax = 0.0f;
      for (int i = 0; i < n; ++i) {
        T[i] *= std::max(0.0f, 1.0f - scale * st[i]);
        tmax = std::max(tmax, T[i]);
      }
      if (tmax < kTransmittanceRrThreshold) {
        if (rng.uniform() < kTransmittanceRrStop) {
          for (int i = 0; i < n; ++i) T[i] = 0.0f;
          return;
        }
        const float k = 1.0f / (1.0f - kTransmittanceRrStop);
        for (int i = 0; i < n; ++i) T[i] *= k;
      }
    }
  }
}

template <int kLanes>
void PathTracer::trace_lanes(const Ray& camera_ray, Rng& rng, PathScratch& s) const {
  const int n = lane_count<kLanes>(s);
  ++s.path_id;
  if (s.path_id == 0) {  // wrapped: forget every stamp
    std::fill(s.material_stamp.begin(), s.material_stamp.end(), 0u);
    s.path_id = 1;
  }
  float* __restrict w = s.weight.data();
  float* env = s.environment.data();  // not restrict: re-pointed at a fluorescent event
  float* __restrict sa = s.sigma_a.data();
  float* __restrict ss = s.sigma_s.data();
  float* __restrict sn = s.sigma_n.data();
  float* __restrict f = s.phase.data();
  float* em = s.emission.data();
  for (int i = 0; i < n; ++i) {
    w[i] = 1.0f;
    env[i] = 0.0f;
    em[i] = 0.0f;
  }
  std::fill(s.directional.begin(), s.directional.end(), 0.0f);
  // Where light seen from here on goes: the diagonal results, or after a fluorescent event the
  // in side of the rank-one term (fl_*).
  float* dir_out = s.directional.data();
  s.fl_active = false;
  bool isotropic = false;  // the last event was a fluorescent re-emission (phase 1/4π)

  Eigen::Vector3d pos = camera_ray.origin;
  Eigen::Vector3d dir = camera_ray.direction;
  double t_enter, t_exit;
  if (!intersect_box(camera_ray, m_medium->bounds_min, m_medium->bounds_max, t_enter, t_exit)) {
    for (int i = 0; i < n; ++i) env[i] = 1.0f;
    add_escape(dir, 0.0, w, dir_out, s);
    return;
  }
  double phase_pdf = 0.0;  // density of dir's last draw from the phase function (0: camera ray)
  ++s.counters.paths_in_volume;
  int bounces = 0;
  const std::int64_t step_limit = s.counters.collisions + s.counters.shadow_steps + kMaxPathSteps;
  auto abandon = [&] {
    for (int i = 0; i < n; ++i) env[i] = kAbandoned;
  };
  for (;;) {
    // Free flight: delta tracking with spectral tracking's event probabilities (Kutz et al. 2017,
    // history-aware schemes, event_probability.h): P_e ∝ m_e = R_i(w_i σ_e,i) for e ∈ {absorb,
    // scatter, null}, and each lane's weight multiplied by σ_e,i / (μ̄ P_e). With one lane this is
    // analog delta tracking.
    const Ray ray{pos, dir};
    MajorantTraversal walk(m_grid, ray, t_enter, t_exit);
    MajorantTraversal::Segment seg;
    bool scattered = false;
    int material = 0;
    while (!scattered && walk.next(seg)) {
      ++s.counters.majorant_cells;
      if (seg.majorant <= 0.0f) continue;
      const float mu = seg.majorant;
      const float inv_mu = 1.0f / mu;
      double t = seg.t0;
      for (;;) {
        t -= std::log(rng.uniform()) * inv_mu;
        if (t >= seg.t1) break;
        if (++s.counters.collisions + s.counters.shadow_steps > step_limit) return abandon();
        const Eigen::Vector3d p = pos + t * dir;
        std::uint16_t m;
        float d;
        lookup(p, m, d);
        if (m == Medium::kEmpty || d <= 0.0f) continue;  // σt = 0: a null collision of weight 1
        if (s.material_stamp[m] != s.path_id) evaluate_material(m, s);
        const float* __restrict st = s.sigma_t.data() + static_cast<std::size_t>(m) * n;
        const float* __restrict al = s.albedo.data() + static_cast<std::size_t>(m) * n;
        float ma = 0.0f, ms = 0.0f, mn = 0.0f, mf = 0.0f;
        for (int i = 0; i < n; ++i) {
          const float sig_t = d * st[i];
          ss[i] = sig_t * al[i];
          sa[i] = sig_t - ss[i];
          sn[i] = std::max(0.0f, mu - sig_t);
        }
        const EventCoefficients ev = event_coefficients(m_events[m], n, w, sa, ss, sn);  // event_probability.h
        ma = ev.absorb, ms = ev.scatter, mn = ev.null;
        const float* __restrict fo = nullptr;
        if (m_fluorescent[m]) {
          // The fluorescent source is a fourth event, of "coefficient" d·Φ_i (evaluate_fluorescence);
          // σf itself is in σa (absorbed at the lane's own wavelength).
          fo = s.fl_out.data() + static_cast<std::size_t>(m) * n;
          mf = event_coefficient(m_events[m], n, w, d, fo);
        }
        if (m_emits[m]) {
          // Emission, pbrt-v4's estimator: at every tentative collision, before the event is chosen,
          // w_i σa,i Le,i / μ̄ (collisions come at rate μ̄, so the sum estimates ∫ T σa Le ds; the
          // absorption event then contributes nothing and the null and scattering events keep their
          // weights, which stays unbiased whatever the event probabilities).
          const float* __restrict le = s.emission_le.data() + static_cast<std::size_t>(m) * n;
          for (int i = 0; i < n; ++i) em[i] += w[i] * sa[i] * le[i] * inv_mu;
        }
        const float c = ma + ms + mf + mn;  // mf = 0 without fluorescence: the sum as before
        if (!(c > 0.0f)) return;
        const float xi = rng.uniform() * c;
        if (xi < ma) return;  // absorbed: no emission, the path ends
        if (xi < ma + ms) {
          if constexpr (kLanes != 1) {  // one lane: the factor is exactly 1 (analog tracking)
            const float k = c / (mu * ms);
            for (int i = 0; i < n; ++i) w[i] *= ss[i] * k;
          }
          pos = p;
          material = m;
          scattered = true;
          isotropic = false;
          break;
        }
        if (mf > 0.0f && xi < ma + ms + mf) {
          fluoresce(m, d, c / (mu * mf), rng, s);
          if (env != s.fl_environment.data()) {
            env = s.fl_environment.data();
            em = s.fl_emission.data();
            dir_out = s.fl_directional.data();
          }
          pos = p;
          material = m;
          scattered = true;
          isotropic = true;
          break;
        }
        if constexpr (kLanes != 1) {
          const float k = c / (mu * mn);
          for (int i = 0; i < n; ++i) w[i] *= sn[i] * k;
        }
      }
    }
    if (!scattered) {
      // Escaped: the unit environment (and the environment maps) seen with the path's weight.
      for (int i = 0; i < n; ++i) env[i] += w[i];
      add_escape(dir, phase_pdf, w, dir_out, s);
      return;
    }
    if (m_max_bounces >= 0 && bounces >= m_max_bounces) return;
    ++bounces;

    const float* __restrict g = isotropic ? s.zero_g.data() : s.g.data() + static_cast<std::size_t>(material) * n;
    const bool g_constant = kLanes == 1 || isotropic || m_g_constant[material];

    // Next-event estimation of every light with its own layer (LightSampler: a direction toward
    // the light and its radiance / density), transmittance by ratio tracking up to the light (the
    // box's exit for distant lights). Environment maps weight the sample by the power heuristic
    // against the density q(ω) the phase sampling below draws ω with (q = Σ_j w_j p_j / Σ_j w_j
    // when g varies across lanes); their escaping paths carry the complementary weight.
    for (std::size_t l = 0; l < m_lights.size(); ++l) {
      LightSample ls;
      if (!m_lights[l].sample(pos, rng, ls)) continue;
      const Eigen::Vector3d& wl = ls.direction;
      const auto cos_theta = static_cast<float>(dir.dot(wl));
      transmittance<kLanes>(pos, wl, rng, s, ls.distance);
      const float* __restrict T = s.transmittance.data();
      float* __restrict out = dir_out + l * static_cast<std::size_t>(n);
      if (g_constant) {
        const float p = hg_phase(cos_theta, g[0]);
        double k = ls.value;
        if (ls.pdf > 0.0) k *= power_heuristic(ls.pdf, p);
        const auto kp = static_cast<float>(std::min(k, kFloatMax)) * p;  // 1/r² of a light at the vertex
        for (int i = 0; i < n; ++i) out[i] += w[i] * kp * T[i];
      } else {
        for (int i = 0; i < n; ++i) f[i] = hg_phase(cos_theta, g[i]);
        double k = ls.value;
        if (ls.pdf > 0.0) {
          float total = 0.0f, mix = 0.0f;
          for (int i = 0; i < n; ++i) {
            total += w[i];
            mix += w[i] * f[i];
          }
          k *= total > 0.0f ? power_heuristic(ls.pdf, mix / total) : 0.0;
        }
        const auto kf = static_cast<float>(std::min(k, kFloatMax));
        for (int i = 0; i < n; ++i) out[i] += w[i] * kf * f[i] * T[i];
      }
    }

    // New direction from the phase function. With g varying across lanes: one-sample MIS over the
    // lanes' lobes with the balance heuristic (Veach 1997, §9.2.4), the lobe chosen in proportion to
    // the lanes' current weights, c_j = w_j / W with W = Σ_j w_j. The direction's density is then
    // q(ω) = Σ_j c_j p_j(ω) and lane i is weighted by p_i(ω) / q(ω):
    //   w_i' = w_i p_i / q = W · w_i p_i / Σ_j w_j p_j.
    // Unbiased: c is fixed before ω is drawn and q > 0 wherever any p_i > 0 (HG lobes with |g| < 1
    // cover the sphere), so E[w_i p_i(ω)/q(ω)] = w_i ∫ p_i = w_i (the phase function's normalisation).
    // Bounded: the denominator holds the term w_i p_i, so w_i' ≤ W; and Σ_i w_i' = W exactly, so the
    // sum of the lane weights never changes at a scattering and no lane exceeds it (≤ n · max_j w_j,
    // the per-lane factor w_i'/w_i ≤ 1/c_i). With uniform c (the previous estimator, factor p_i /
    // mean_j p_j ≤ n per scattering) the factors multiply along the path without bound.
    float cos_theta;
    if (g_constant) {
      cos_theta = hg_sample_cos(g[0], rng.uniform());
      if (m_any_mis) phase_pdf = hg_phase(cos_theta, g[0]);
    } else {
      float total = 0.0f;
      for (int i = 0; i < n; ++i) total += w[i];
      if (!(total > 0.0f)) return;
      // Lane j with probability w_j / W (inverse CDF; lanes of weight 0 are never chosen).
      const float target = rng.uniform() * total;
      int j = 0;
      float cdf = w[0];
      while (j < n - 1 && cdf <= target) cdf += w[++j];
      while (j > 0 && w[j] <= 0.0f) --j;  // float rounding past the end: the last lane that can be chosen
      cos_theta = hg_sample_cos(g[j], rng.uniform());
      float mix = 0.0f;  // Σ_j w_j p_j = W · q(ω)
      for (int i = 0; i < n; ++i) {
        f[i] = hg_phase(cos_theta, g[i]);
        mix += w[i] * f[i];
      }
      if (!(mix > 0.0f)) return;
      phase_pdf = mix / total;
      const float k = total / mix;
      for (int i = 0; i < n; ++i) w[i] *= f[i] * k;
    }
    dir = direction_around(dir, cos_theta, rng.uniform_double()).normalized();

    // Russian roulette on the largest lane weight (unbiased: survivors divided by the probability).
    float wmax = 0.0f;
    for (int i = 0; i < n; ++i) wmax = std::max(wmax, w[i]);
    if (!(wmax > 0.0f)) return;
    if (wmax < 1.0f) {
      if (rng.uniform() >= wmax) return;
      const float k = 1.0f / wmax;
      for (int i = 0; i < n; ++i) w[i] *= k;
    }
    const Ray next{pos, dir};
    if (!intersect_box(next, m_medium->bounds_min, m_medium->bounds_max, t_enter, t_exit)) {
      for (int i = 0; i < n; ++i) env[i] += w[i];
      add_escape(dir, phase_pdf, w, dir_out, s);
      return;
    }
  }
}

void PathTracer::fluoresce(int m, float density, float k, Rng& rng, PathScratch& s) const {
  // The event's weight on the out side, a_i = w_i·d·Φ_i·c/(μ̄·mf) (the spectral-tracking factor of
  // the event), then the lanes carry λin with weights p_j. The path's transport is rank one from
  // here on: M[out][in] += a[out]·(what lane in sees). A later event keeps a and scales the lanes by
  // Σ_i a'_i (Φ and p are rank one too, so the state stays rank one however many events chain).
  // The in side gets wavelengths of its own, λ'_j = lo_j + u'·Δλ_j with a fresh u': with the out
  // side's jitter, E[f(λ_out)·g(λ_in)] over the shared u is not the product of the bin averages
  // (a bias of 30 % in the tests). Φ was evaluated with Λ at the old wavelengths; the estimate of
  // ∫ σf·λ·L̄ dλ must use the new ones, hence the factor Λ'/Λ (the event's probability may use any Λ).
  const int n = s.lanes;
  float* w = s.weight.data();
  const float* fo = s.fl_out.data() + static_cast<std::size_t>(m) * n;
  const double old_sum = s.fl_lambda_sum[m];
  float total = 0.0f;  // later events: Σ_i a'_i
  if (!s.fl_active) {
    for (int i = 0; i < n; ++i) s.fl_a[i] = w[i] * density * fo[i] * k;
  } else {
    for (int i = 0; i < n; ++i) total += w[i] * density * fo[i] * k;
  }
  const double u = rng.uniform_double();
  for (int i = 0; i < n; ++i) s.lambda_nm[i] = static_cast<float>(s.lo_nm[i] + u * s.width_nm[i]);
  if (++s.path_id == 0) {  // every material is evaluated anew at the new wavelengths
    std::fill(s.material_stamp.begin(), s.material_stamp.end(), 0u);
    s.path_id = 1;
  }
  evaluate_material(m, s);
  const auto ratio = static_cast<float>(old_sum > 0.0 ? s.fl_lambda_sum[m] / old_sum : 0.0);
  const float* fi = s.fl_in.data() + static_cast<std::size_t>(m) * n;
  float pmax = 0.0f;
  for (int j = 0; j < n; ++j) pmax = std::max(pmax, fi[j]);
  if (!s.fl_active) {
    // First event: the diagonal results so far stay; the in side starts empty. The lanes' largest
    // weight is made 1 (its scale moved to a) so that Russian roulette sees a unit path.
    for (int i = 0; i < n; ++i) s.fl_a[i] *= ratio * pmax;
    std::fill(s.fl_environment.begin(), s.fl_environment.end(), 0.0f);
    std::fill(s.fl_emission.begin(), s.fl_emission.end(), 0.0f);
    std::fill(s.fl_directional.begin(), s.fl_directional.end(), 0.0f);
    s.fl_active = true;
    const float inv = pmax > 0.0f ? 1.0f / pmax : 0.0f;
    for (int j = 0; j < n; ++j) w[j] = fi[j] * inv;
  } else {
    total *= ratio;
    for (int j = 0; j < n; ++j) w[j] = total * fi[j];
  }
}

template void PathTracer::trace_lanes<1>(const Ray&, Rng&, PathScratch&) const;
template void PathTracer::trace_lanes<0>(const Ray&, Rng&, PathScratch&) const;

}  // namespace prizma::render
