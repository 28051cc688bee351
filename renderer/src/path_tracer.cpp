#include "prizma/render/path_tracer.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "lanes.h"
#include "majorant_sampler.h"
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

// The lanes of a per-lane array, or of row `row` of a [row][lanes] array.
template <int kLanes>
Lanes<kLanes> lanes_of(std::vector<float>& v, int n, std::size_t row = 0) {
  return Lanes<kLanes>(v.data() + row * static_cast<std::size_t>(n), n);
}
template <int kLanes>
ConstLanes<kLanes> lanes_of(const std::vector<float>& v, int n, std::size_t row = 0) {
  return ConstLanes<kLanes>(v.data() + row * static_cast<std::size_t>(n), n);
}

// Calls put(i, s.eval(λ_i)) for each lane's wavelength λ_i (float, as the cache holds them), with
// the values Spectrum::eval returns (the same table interval, the same interpolation expression),
// without a binary search per lane: the interval is guessed as if the table were evenly spaced
// (CSV tables usually are: 1 nm) and corrected by steps until it is std::upper_bound's, which it
// then is for any increasing table. The binary searches were a fifth of a path's time on
// data/scenes/bench_peer.json.
template <class Put>
void eval_lanes(const spectral::Spectrum& s, const float* lambda_nm, int n, Put&& put) {
  if (s.is_constant()) {
    const double c = s.eval(0.0);
    for (int i = 0; i < n; ++i) put(i, c);
    return;
  }
  const std::vector<double>& x = s.wavelengths_nm();
  const std::vector<double>& y = s.values();
  const std::size_t m = x.size();
  const double per_nm = m >= 2 ? static_cast<double>(m - 1) / (x.back() - x.front()) : 0.0;
  for (int i = 0; i < n; ++i) {
    const double l = lambda_nm[i];
    if (m < 2 || !(l >= x.front() && l <= x.back())) {
      put(i, 0.0);
      continue;
    }
    // j: the first entry > l (x[j − 1] ≤ l < x[j]; j = m when l is the last entry).
    auto j = static_cast<std::size_t>((l - x.front()) * per_nm) + 1;
    j = std::min(j, m);
    while (j < m && !(l < x[j])) ++j;
    while (j > 1 && l < x[j - 1]) --j;
    if (j >= m) {
      put(i, y.back());
      continue;
    }
    const std::size_t k = j - 1;
    const double t = (l - x[k]) / (x[k + 1] - x[k]);
    put(i, y[k] + t * (y[k + 1] - y[k]));
  }
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
    : m_medium(&scene.medium), m_simd(default_simd_level()), m_max_bounces(scene.settings.max_bounces) {
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
    m_fl_excitation.emplace_back();
    if (fl) {
      const double area = fluorescence_emission_area(mat.fluorescence.emission);
      if (!(area > 0.0) || !std::isfinite(area) || !(mat.fluorescence.quantum_yield <= 1.0))
        throw spectral::InputError("medium", "material \"" + mat.name + "\": fluorescence needs an emission of positive area and q in [0, 1]");
      m_fl_emission.back() = mat.fluorescence.emission.scaled(1.0 / area);
      m_fl_excitation.back() = ExcitationSampler(mat.fluorescence.absorption, lambda_lo_nm, lambda_hi_nm);
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
  s.in.lambda_nm.assign(n, 0.0f);
  s.in.width_nm.assign(n, 0.0f);
  s.in.lo_nm.assign(n, 0.0f);
  MaterialCache& c = s.cache;
  c.lambda_nm.assign(n, 0.0f);
  for (auto* v : {&c.sigma_t, &c.albedo, &c.g, &c.emission_le}) v->assign(nm * n, 0.0f);
  c.stamp.assign(nm, 0);
  c.path_id = 0;
  PathWork& w = s.work;
  for (auto* v : {&w.weight, &w.transmittance, &w.optical_depth, &w.phase, &w.sigma_a, &w.sigma_s, &w.sigma_n})
    v->assign(n, 0.0f);
  PathResult& out = s.out;
  out.environment.assign(n, 0.0f);
  out.emission.assign(n, 0.0f);
  out.directional.assign(m_lights.size() * n, 0.0f);
  out.fl_active = false;
  const bool any_fluorescent = std::any_of(m_medium->materials.begin(), m_medium->materials.end(),
                                           [](const Material& m) { return m.fluorescent; });
  if (any_fluorescent) {
    c.fl_out.assign(nm * n, 0.0f);
    c.fl_in.assign(nm * n, 0.0f);
    c.fl_lambda_sum.assign(nm, 0.0);
    w.zero_g.assign(n, 0.0f);
    for (auto* v : {&out.fl_a, &out.fl_environment, &out.fl_emission}) v->assign(n, 0.0f);
    out.fl_directional.assign(m_lights.size() * n, 0.0f);
  }
}

void PathTracer::evaluate_material(int m, PathScratch& s) const {
  // Once per path and material: the spectra at the path's wavelengths, so that a collision costs a
  // voxel lookup and a few multiplies.
  const Material& mat = m_medium->materials[m];
  const int n = s.lanes;
  float* st = s.cache.sigma_t.data() + static_cast<std::size_t>(m) * n;
  float* al = s.cache.albedo.data() + static_cast<std::size_t>(m) * n;
  float* g = s.cache.g.data() + static_cast<std::size_t>(m) * n;
  float* le = s.cache.emission_le.data() + static_cast<std::size_t>(m) * n;
  const float* lambda = s.cache.lambda_nm.data();
  eval_lanes(mat.sigma_t_per_unit, lambda, n, [st](int i, double v) { st[i] = static_cast<float>(std::max(0.0, v)); });
  eval_lanes(mat.albedo, lambda, n, [al](int i, double v) { al[i] = static_cast<float>(std::clamp(v, 0.0, 1.0)); });
  eval_lanes(mat.anisotropy, lambda, n,
             [g](int i, double v) { g[i] = static_cast<float>(std::clamp(v, -0.9999, 0.9999)); });
  if (m_emits[m])
    eval_lanes(mat.emission, lambda, n, [le](int i, double v) { le[i] = static_cast<float>(std::max(0.0, v)); });
  if (mat.fluorescent) evaluate_fluorescence(m, s);
  s.cache.stamp[m] = s.cache.path_id;
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
  float* st = s.cache.sigma_t.data() + static_cast<std::size_t>(m) * n;
  float* al = s.cache.albedo.data() + static_cast<std::size_t>(m) * n;
  float* fo = s.cache.fl_out.data() + static_cast<std::size_t>(m) * n;
  float* fi = s.cache.fl_in.data() + static_cast<std::size_t>(m) * n;
  double big_lambda = 0.0;
  for (int i = 0; i < n; ++i) {
    const double l = s.cache.lambda_nm[i];
    const auto sf = static_cast<float>(std::max(0.0, mat.fluorescence.absorption.eval(l)));
    const float st0 = st[i];
    st[i] = st0 + sf;
    al[i] = st[i] > 0.0f ? al[i] * (st0 / st[i]) : 0.0f;
    fi[i] = static_cast<float>(static_cast<double>(s.in.width_nm[i]) * sf * l);
    big_lambda += fi[i];
  }
  // One lane (--wavelength-sampling single): λin is drawn over the whole range, Λ = ∫ σf·λ dλ.
  if (n == 1) big_lambda = m_fl_excitation[m].total();
  s.cache.fl_lambda_sum[m] = big_lambda;
  if (!m_fluorescent[m] || !(big_lambda > 0.0)) {
    std::fill(fo, fo + n, 0.0f);
    std::fill(fi, fi + n, 0.0f);
    return;
  }
  const double q = mat.fluorescence.quantum_yield;
  for (int i = 0; i < n; ++i) {
    const double l = s.cache.lambda_nm[i];
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

void PathTracer::set_simd_level(SimdLevel level) {
  const std::vector<SimdLevel> levels = supported_simd_levels();
  if (std::find(levels.begin(), levels.end(), level) == levels.end())
    throw spectral::InputError("simd", "the tracer has no " + std::string(simd_level_name(level)) + " level on this CPU");
  m_simd = level;
}

void PathTracer::trace(const Ray& ray, Rng& rng, PathScratch& s) const {
  switch (m_simd) {
    case SimdLevel::Avx512:
      trace_avx512(ray, rng, s);
      return;
    case SimdLevel::Avx2:
      trace_avx2(ray, rng, s);
      return;
    case SimdLevel::Sse4:  // not a tracer level: supported_simd_levels() never lists it
    case SimdLevel::Baseline:
      break;
  }
  trace_baseline(ray, rng, s);
}

void PathTracer::trace_baseline(const Ray& ray, Rng& rng, PathScratch& s) const {
  if (s.lanes == 1)
    trace_lanes<1>(ray, rng, s);
  else
    trace_lanes<0>(ray, rng, s);
}

// The other levels: trace_baseline with everything it calls in this file inlined (flatten) and
// compiled for the level's instruction set, so that GCC vectorises the per-lane loops 8 or 16
// floats wide. Bit-identical to the baseline: this file is compiled with -ffp-contract=off (no
// FMA from a·b + c), the vectoriser keeps IEEE semantics (no reassociated sums or maxima without
// -ffast-math), and the few calls that stay calls (libm, spectra, light samplers) are the same
// functions at every level. tests/render/test_simd_levels.cpp compares the levels bit for bit.
#if defined(__x86_64__) && defined(__GNUC__)
// 256-bit vectors on the AVX-512 level: GCC takes the preference in the target string; clang does
// not know it there (it warns and ignores the whole attribute), so its AVX-512 level keeps clang's
// default width. Only the sanitizer tree is built with clang.
#if defined(__clang__)
#define PRIZMA_TRACE_AVX512_TARGET "avx2,fma,avx512f,avx512vl,avx512bw,avx512dq"
#else
#define PRIZMA_TRACE_AVX512_TARGET "avx2,fma,avx512f,avx512vl,avx512bw,avx512dq,prefer-vector-width=256"
#endif
__attribute__((target("avx2,fma"), flatten)) void PathTracer::trace_avx2(const Ray& ray, Rng& rng,
                                                                          PathScratch& s) const {
  trace_baseline(ray, rng, s);
}
__attribute__((target(PRIZMA_TRACE_AVX512_TARGET), flatten)) void PathTracer::trace_avx512(
    const Ray& ray, Rng& rng, PathScratch& s) const {
  trace_baseline(ray, rng, s);
}
#else
void PathTracer::trace_avx2(const Ray& ray, Rng& rng, PathScratch& s) const { trace_baseline(ray, rng, s); }
void PathTracer::trace_avx512(const Ray& ray, Rng& rng, PathScratch& s) const { trace_baseline(ray, rng, s); }
#endif
#undef PRIZMA_TRACE_AVX512_TARGET

// The state of a path between its events.
template <int kLanes>
struct PathTracer::PathState {
  int n;             // lanes
  Lanes<kLanes> w;   // throughput per lane
  // Where light seen from here on goes: the diagonal results, or after a fluorescent event the in
  // side of the rank-one term (out.fl_*).
  float* env;
  float* em;
  float* dir_out;
  Eigen::Vector3d pos, dir;
  double t_enter = 0.0, t_exit = 0.0;  // the current ray's interval inside the box
  double phase_pdf = 0.0;  // density of dir's last draw from the phase function (0: camera ray)
  int material = 0;        // at the last scattering
  bool isotropic = false;  // the last event was a fluorescent re-emission (phase 1/4π)
  std::int64_t step_limit = 0;  // collisions + shadow steps at which the path is abandoned

  Lanes<kLanes> lanes(float* p) const { return Lanes<kLanes>(p, n); }
};

void PathTracer::add_escape(const Eigen::Vector3d& dir, double phase_pdf, const float* w, float* lights_out,
                            PathScratch& s) const {
  const int n = s.lanes;
  for (int k : m_escape_lights) {
    const auto radiance = static_cast<float>(m_lights[k].escape_radiance(dir, phase_pdf));
    if (!(radiance > 0.0f)) continue;
    Lanes<0>(lights_out + static_cast<std::size_t>(k) * n, n) += ConstLanes<0>(w, n) * radiance;
  }
}

template <int kLanes>
void PathTracer::transmittance(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, Rng& rng,
                               PathScratch& s, double t_max) const {
  // Residual ratio tracking (Novák, Georgiev, Hanika, Jarosz 2014) against the cells' controls,
  // every lane at once: T = exp(−∫ σc ds) · Π (1 − (σt − σc)/μ̄r) over tentative collisions at the
  // residual rate μ̄r, with Russian roulette at the steps once T is small. A cell without a
  // control (σc = 0, μ̄r = its majorant) is plain ratio tracking, T *= 1 − σt/μ̄; a homogeneous
  // cell (μ̄r = 0) takes no steps. The controls' optical depth τ is summed per lane and applied
  // once at the end.
  const int n = lane_count<kLanes>(s);
  const Lanes<kLanes> T = lanes_of<kLanes>(s.work.transmittance, n);
  const Lanes<kLanes> tau = lanes_of<kLanes>(s.work.optical_depth, n);
  T = 1.0f;
  const Ray ray{origin, dir};
  double t_enter, t_exit;
  if (!intersect_box(ray, m_medium->bounds_min, m_medium->bounds_max, t_enter, t_exit)) return;
  t_exit = std::min(t_exit, t_max);  // a light inside or before the box: only the medium up to it
  if (!(t_exit > t_enter)) return;
  const std::int64_t step_limit = s.counters.shadow_steps + kMaxPathSteps;
  const CellControl* control = nullptr;  // the current cell's
  // The controls' optical depth τ_i = Σ_cells d_c·ℓ·σt,i: while consecutive cells share a control
  // material m, the scalar D = Σ d_c·ℓ (one multiply-add per cell), added to the lanes as D·σt_m
  // when the material changes and at the end.
  std::uint16_t run_material = CellControl::kNone;
  float run_depth = 0.0f;      // D of the current run
  float run_sigma_min = 0.0f;  // the least lane of σt_m
  bool any_control = false;    // tau holds a flushed run
  float tau_min = 0.0f;        // the least lane of tau
  auto flush = [&]() {
    if (run_material == CellControl::kNone || !(run_depth > 0.0f)) return;
    const ConstLanes<kLanes> sigma_t = lanes_of<kLanes>(std::as_const(s.cache.sigma_t), n, run_material);
    if (any_control)
      tau += sigma_t * run_depth;
    else
      tau = sigma_t * run_depth;
    any_control = true;
    tau_min = partial::min_from_infinity(tau, n);
    run_depth = 0.0f;
  };
  float t_res_max = 1.0f;  // the largest lane of T (the residual product)
  // After a step, the roulette on a bound of the largest transmittance, T_max·exp(−min τ) with
  // min τ ≥ tau_min + D·σt_min (none between cells: crossing a homogeneous cell is exact and costs
  // no random number); false: stopped.
  auto roulette = [&]() {
    if (!(t_res_max < kTransmittanceRrThreshold)) {
      const float depth_lo = tau_min + run_depth * run_sigma_min;
      if (!(depth_lo > 0.0f) || !(t_res_max * std::exp(-depth_lo) < kTransmittanceRrThreshold)) return true;
    }
    if (rng.uniform() < kTransmittanceRrStop) {
      T = 0.0f;
      return false;
    }
    T *= 1.0f / (1.0f - kTransmittanceRrStop);
    t_res_max = T.max();
    return true;
  };
  auto on_segment = [&](const MajorantTraversal::Segment& seg, float& mu) {
    if (!(seg.majorant > 0.0f)) return true;  // empty: no steps
    control = &m_grid.control(seg.cell);
    mu = control->residual;
    const std::uint16_t m = control->material;
    if (m == CellControl::kNone) return true;
    if (m != run_material) {
      flush();
      run_material = m;
      if (!s.cache.holds(m)) evaluate_material(m, s);
      run_sigma_min = partial::min_from_infinity(s.cache.sigma_t.data() + static_cast<std::size_t>(m) * n, n);
    }
    run_depth += control->density * static_cast<float>(seg.t1 - seg.t0);
    return true;
  };
  const bool reached = sample_segments(m_grid, ray, t_enter, t_exit, rng, s.counters.majorant_cells, on_segment,
                                       [&](const TentativeCollision& tc) {
    if (++s.counters.shadow_steps > step_limit) {
      T = kAbandoned;
      return false;
    }
    std::uint16_t m;
    float d;
    lookup(tc.p, m, d);
    const std::uint16_t mc = control->material;
    if (mc == CellControl::kNone || m != mc) {
      if (m == Medium::kEmpty || d <= 0.0f) d = 0.0f;
      if (mc == CellControl::kNone) {  // plain ratio tracking: T *= 1 − σt/μ̄
        if (d == 0.0f) return true;
        if (!s.cache.holds(m)) evaluate_material(m, s);
        const ConstLanes<kLanes> sigma_t = lanes_of<kLanes>(std::as_const(s.cache.sigma_t), n, m);
        T *= lane_max(0.0f, 1.0f - (d * tc.inv_mu) * sigma_t);
      } else {  // another material than the control's (only on a cell's boundary, by rounding)
        const ConstLanes<kLanes> sigma_c = lanes_of<kLanes>(std::as_const(s.cache.sigma_t), n, mc);
        const float kc = control->density * tc.inv_mu;
        if (d == 0.0f) {
          T *= 1.0f + kc * sigma_c;
        } else {
          if (!s.cache.holds(m)) evaluate_material(m, s);
          const ConstLanes<kLanes> sigma_t = lanes_of<kLanes>(std::as_const(s.cache.sigma_t), n, m);
          T *= lane_max(0.0f, 1.0f - ((d * tc.inv_mu) * sigma_t - kc * sigma_c));
        }
      }
    } else {  // σt − σc = (d − d_c)·σt_m
      const ConstLanes<kLanes> sigma_t = lanes_of<kLanes>(std::as_const(s.cache.sigma_t), n, m);
      T *= lane_max(0.0f, 1.0f - ((d - control->density) * tc.inv_mu) * sigma_t);
    }
    t_res_max = T.max();
    return roulette();
  });
  if (!reached) return;
  flush();
  if (any_control) T *= lane_map([](float x) { return std::exp(-x); }, ConstLanes<kLanes>(tau));
}

void PathTracer::estimate_transmittance(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_max,
                                        Rng& rng, PathScratch& s) const {
  MaterialCache& cache = s.cache;
  std::copy(s.in.lambda_nm.begin(), s.in.lambda_nm.end(), cache.lambda_nm.begin());
  cache.new_wavelengths();
  if (s.lanes == 1)
    transmittance<1>(origin, dir, rng, s, t_max);
  else
    transmittance<0>(origin, dir, rng, s, t_max);
}

template <int kLanes>
PathTracer::FlightEnd PathTracer::free_flight(PathState<kLanes>& v, Rng& rng, PathScratch& s) const {
  // Delta tracking with spectral tracking's event probabilities (Kutz et al. 2017, history-aware
  // schemes, event_probability.h): P_e ∝ m_e = R_i(w_i σ_e,i) for e ∈ {absorb, scatter, null}, and
  // each lane's weight multiplied by σ_e,i / (μ̄ P_e). With one lane this is analog delta tracking.
  const int n = v.n;
  const Lanes<kLanes>& w = v.w;
  const Lanes<kLanes> sa = lanes_of<kLanes>(s.work.sigma_a, n);
  const Lanes<kLanes> ss = lanes_of<kLanes>(s.work.sigma_s, n);
  const Lanes<kLanes> sn = lanes_of<kLanes>(s.work.sigma_n, n);
  FlightEnd end = FlightEnd::Escaped;
  const Ray ray{v.pos, v.dir};
  sample_majorant(m_grid, ray, v.t_enter, v.t_exit, rng, s.counters.majorant_cells, [&](const TentativeCollision& tc) {
    if (++s.counters.collisions + s.counters.shadow_steps > v.step_limit) {
      end = FlightEnd::Abandoned;
      return false;
    }
    std::uint16_t m;
    float d;
    lookup(tc.p, m, d);
    if (m == Medium::kEmpty || d <= 0.0f) return true;  // σt = 0: a null collision of weight 1
    if (!s.cache.holds(m)) evaluate_material(m, s);
    const ConstLanes<kLanes> sigma_t = lanes_of<kLanes>(std::as_const(s.cache.sigma_t), n, m);
    const ConstLanes<kLanes> albedo = lanes_of<kLanes>(std::as_const(s.cache.albedo), n, m);
    const float mu = tc.mu;
    // The three coefficients in one loop over the lanes, then the scheme's m_e in fixed-order partial
    // maxima and sums: both vectorise, with the same bits at every SIMD level (event_probability.h).
    const EventCoefficients ev = collision_coefficients(m_events[m], n, d, mu, sigma_t.data(), albedo.data(),
                                                        w.data(), sa.data(), ss.data(), sn.data());
    const float ma = ev.absorb, ms = ev.scatter, mn = ev.null;
    float mf = 0.0f;
    if (m_fluorescent[m]) {
      // The fluorescent source is a fourth event, of "coefficient" d·Φ_i (evaluate_fluorescence);
      // σf itself is in σa (absorbed at the lane's own wavelength).
      mf = event_coefficient(m_events[m], n, w.data(), d, lanes_of<kLanes>(std::as_const(s.cache.fl_out), n, m).data());
    }
    if (m_emits[m]) {
      // Emission, pbrt-v4's estimator: at every tentative collision, before the event is chosen,
      // w_i σa,i Le,i / μ̄ (collisions come at rate μ̄, so the sum estimates ∫ T σa Le ds; the
      // absorption event then contributes nothing and the null and scattering events keep their
      // weights, which stays unbiased whatever the event probabilities).
      v.lanes(v.em) += w * sa * lanes_of<kLanes>(std::as_const(s.cache.emission_le), n, m) * tc.inv_mu;
    }
    const float c = ma + ms + mf + mn;  // mf = 0 without fluorescence: the sum as before
    if (!(c > 0.0f)) {
      end = FlightEnd::Absorbed;
      return false;
    }
    const float xi = rng.uniform() * c;
    if (xi < ma) {  // absorbed: no emission, the path ends
      end = FlightEnd::Absorbed;
      return false;
    }
    if (xi < ma + ms) {
      // One lane: exactly 1 (analog tracking) unless a fluorescent event adds d·Φ to the sum c.
      if (kLanes != 1 || mf > 0.0f) w *= ss * (c / (mu * ms));
      v.pos = tc.p;
      v.material = m;
      v.isotropic = false;
      end = FlightEnd::Scattered;
      return false;
    }
    if (mf > 0.0f && xi < ma + ms + mf) {
      fluoresce(m, d, c / (mu * mf), rng, s);
      v.env = s.out.fl_environment.data();
      v.em = s.out.fl_emission.data();
      v.dir_out = s.out.fl_directional.data();
      v.pos = tc.p;
      v.material = m;
      v.isotropic = true;
      end = FlightEnd::Scattered;
      return false;
    }
    if (kLanes != 1 || mf > 0.0f) w *= sn * (c / (mu * mn));
    return true;
  });
  return end;
}

template <int kLanes>
void PathTracer::estimate_lights(PathState<kLanes>& v, ConstLanes<kLanes> g, bool g_constant, Rng& rng,
                                 PathScratch& s) const {
  // Next-event estimation of every light with its own layer (LightSampler: a direction toward the
  // light and its radiance / density), transmittance by ratio tracking up to the light (the box's
  // exit for distant lights). Environment maps weight the sample by the power heuristic against
  // the density q(ω) the phase sampling draws ω with (q = Σ_j w_j p_j / Σ_j w_j when g varies
  // across lanes); their escaping paths carry the complementary weight.
  const int n = v.n;
  const Lanes<kLanes>& w = v.w;
  const Lanes<kLanes> f = lanes_of<kLanes>(s.work.phase, n);
  const ConstLanes<kLanes> T = lanes_of<kLanes>(std::as_const(s.work.transmittance), n);
  for (std::size_t l = 0; l < m_lights.size(); ++l) {
    LightSample ls;
    if (!m_lights[l].sample(v.pos, rng, ls)) continue;
    const Eigen::Vector3d& wl = ls.direction;
    const auto cos_theta = static_cast<float>(v.dir.dot(wl));
    transmittance<kLanes>(v.pos, wl, rng, s, ls.distance);
    const Lanes<kLanes> out = v.lanes(v.dir_out + l * static_cast<std::size_t>(n));
    if (g_constant) {
      const float p = hg_phase(cos_theta, g[0]);
      double k = ls.value;
      if (ls.pdf > 0.0) k *= power_heuristic(ls.pdf, p);
      const auto kp = static_cast<float>(std::min(k, kFloatMax)) * p;  // 1/r² of a light at the vertex
      out += w * kp * T;
    } else {
      f = lane_map([cos_theta](float gi) { return hg_phase(cos_theta, gi); }, g);
      double k = ls.value;
      if (ls.pdf > 0.0) {
        const float total = w.sum(), mix = sum_over(w * f, n);
        k *= total > 0.0f ? power_heuristic(ls.pdf, mix / total) : 0.0;
      }
      const auto kf = static_cast<float>(std::min(k, kFloatMax));
      out += w * kf * f * T;
    }
  }
}

template <int kLanes>
bool PathTracer::sample_phase(PathState<kLanes>& v, ConstLanes<kLanes> g, bool g_constant, Rng& rng,
                              PathScratch& s) const {
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
  // False when the path carries nothing any more.
  const int n = v.n;
  const Lanes<kLanes>& w = v.w;
  float cos_theta;
  if (g_constant) {
    cos_theta = hg_sample_cos(g[0], rng.uniform());
    if (m_any_mis) v.phase_pdf = hg_phase(cos_theta, g[0]);
  } else {
    const float total = w.sum();
    if (!(total > 0.0f)) return false;
    // Lane j with probability w_j / W (inverse CDF; lanes of weight 0 are never chosen).
    const float target = rng.uniform() * total;
    int j = 0;
    float cdf = w[0];
    while (j < n - 1 && cdf <= target) cdf += w[++j];
    while (j > 0 && w[j] <= 0.0f) --j;  // float rounding past the end: the last lane that can be chosen
    cos_theta = hg_sample_cos(g[j], rng.uniform());
    const Lanes<kLanes> f = lanes_of<kLanes>(s.work.phase, n);
    f = lane_map([cos_theta](float gi) { return hg_phase(cos_theta, gi); }, g);
    const float mix = sum_over(w * f, n);  // Σ_j w_j p_j = W · q(ω)
    if (!(mix > 0.0f)) return false;
    v.phase_pdf = mix / total;
    w *= f * (total / mix);
  }
  v.dir = direction_around(v.dir, cos_theta, rng.uniform_double()).normalized();
  return true;
}

template <int kLanes>
bool PathTracer::roulette(PathState<kLanes>& v, Rng& rng) const {
  // Russian roulette on the largest lane weight (unbiased: survivors divided by the probability).
  const float wmax = v.w.max();
  if (!(wmax > 0.0f)) return false;
  if (wmax < 1.0f) {
    if (rng.uniform() >= wmax) return false;
    v.w *= 1.0f / wmax;
  }
  return true;
}

template <int kLanes>
void PathTracer::trace_lanes(const Ray& camera_ray, Rng& rng, PathScratch& s) const {
  const int n = lane_count<kLanes>(s);
  MaterialCache& cache = s.cache;
  std::copy(s.in.lambda_nm.begin(), s.in.lambda_nm.end(), cache.lambda_nm.begin());
  cache.new_wavelengths();
  PathResult& out = s.out;
  PathState<kLanes> v{n, lanes_of<kLanes>(s.work.weight, n), out.environment.data(), out.emission.data(),
                      out.directional.data(), camera_ray.origin, camera_ray.direction};
  v.w = 1.0f;
  v.lanes(v.env) = 0.0f;
  v.lanes(v.em) = 0.0f;
  std::fill(out.directional.begin(), out.directional.end(), 0.0f);
  out.fl_active = false;

  if (!intersect_box(camera_ray, m_medium->bounds_min, m_medium->bounds_max, v.t_enter, v.t_exit)) {
    v.lanes(v.env) = 1.0f;
    add_escape(v.dir, 0.0, v.w.data(), v.dir_out, s);
    return;
  }
  ++s.counters.paths_in_volume;
  int bounces = 0;
  v.step_limit = s.counters.collisions + s.counters.shadow_steps + kMaxPathSteps;
  for (;;) {
    switch (free_flight(v, rng, s)) {
      case FlightEnd::Abandoned:
        v.lanes(v.env) = kAbandoned;
        return;
      case FlightEnd::Absorbed:
        return;
      case FlightEnd::Escaped:  // the unit environment (and the environment maps) seen with the path's weight
        v.lanes(v.env) += v.w;
        add_escape(v.dir, v.phase_pdf, v.w.data(), v.dir_out, s);
        return;
      case FlightEnd::Scattered:
        break;
    }
    if (m_max_bounces >= 0 && bounces >= m_max_bounces) return;
    ++bounces;

    const ConstLanes<kLanes> g = v.isotropic ? lanes_of<kLanes>(std::as_const(s.work.zero_g), n)
                                             : lanes_of<kLanes>(std::as_const(cache.g), n, v.material);
    const bool g_constant = kLanes == 1 || v.isotropic || m_g_constant[v.material];
    estimate_lights(v, g, g_constant, rng, s);
    if (!sample_phase(v, g, g_constant, rng, s)) return;
    if (!roulette(v, rng)) return;
    if (!intersect_box(Ray{v.pos, v.dir}, m_medium->bounds_min, m_medium->bounds_max, v.t_enter, v.t_exit)) {
      v.lanes(v.env) += v.w;
      add_escape(v.dir, v.phase_pdf, v.w.data(), v.dir_out, s);
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
  MaterialCache& cache = s.cache;
  PathResult& out = s.out;
  if (n == 1) {
    // One wavelength per path (--wavelength-sampling single): the path's wavelength becomes λin,
    // drawn with density σf(λ)·λ/Λ (ExcitationSampler; Φ holds Λ), its weight that draw's. The out
    // side keeps the first event's factor a = w·d·Φ·c/(μ̄·mf); a later event's factor scales the in
    // side. The in bin is read off the wavelength, so a later event first closes the segment seen at
    // the previous λin (PathResult::fl_segments): left open, it would be counted in the new λin's bin.
    float& w0 = s.work.weight[0];
    const float event = w0 * density * cache.fl_out[static_cast<std::size_t>(m)] * k;
    if (out.fl_active) out.close_fluorescent_segment(cache.lambda_nm[0]);
    const ExcitationSampler::Draw draw = m_fl_excitation[m].sample(rng.uniform_double());
    cache.lambda_nm[0] = static_cast<float>(draw.lambda_nm);
    cache.new_wavelengths();  // every material is evaluated anew at the new wavelength
    if (!out.fl_active) {
      out.fl_a[0] = event;
      std::fill(out.fl_environment.begin(), out.fl_environment.end(), 0.0f);
      std::fill(out.fl_emission.begin(), out.fl_emission.end(), 0.0f);
      std::fill(out.fl_directional.begin(), out.fl_directional.end(), 0.0f);
      out.fl_segments.clear();
      out.fl_active = true;
      w0 = static_cast<float>(draw.weight);
    } else {
      w0 = event * static_cast<float>(draw.weight);
    }
    return;
  }
  const Lanes<0> w = lanes_of<0>(s.work.weight, n);
  const Lanes<0> a = lanes_of<0>(out.fl_a, n);
  const ConstLanes<0> fo = lanes_of<0>(std::as_const(cache.fl_out), n, m);
  const double old_sum = cache.fl_lambda_sum[m];
  float total = 0.0f;  // later events: Σ_i a'_i
  if (!out.fl_active)
    a = w * density * fo * k;
  else
    total = sum_over(w * density * fo * k, n);
  const double u = rng.uniform_double();
  for (int i = 0; i < n; ++i) cache.lambda_nm[i] = static_cast<float>(s.in.lo_nm[i] + u * s.in.width_nm[i]);
  cache.new_wavelengths();  // every material is evaluated anew at the new wavelengths
  evaluate_material(m, s);
  const auto ratio = static_cast<float>(old_sum > 0.0 ? cache.fl_lambda_sum[m] / old_sum : 0.0);
  const ConstLanes<0> fi = lanes_of<0>(std::as_const(cache.fl_in), n, m);
  const float pmax = fi.max();
  if (!out.fl_active) {
    // First event: the diagonal results so far stay; the in side starts empty. The lanes' largest
    // weight is made 1 (its scale moved to a) so that Russian roulette sees a unit path.
    a *= ratio * pmax;
    std::fill(out.fl_environment.begin(), out.fl_environment.end(), 0.0f);
    std::fill(out.fl_emission.begin(), out.fl_emission.end(), 0.0f);
    std::fill(out.fl_directional.begin(), out.fl_directional.end(), 0.0f);
    out.fl_active = true;
    const float inv = pmax > 0.0f ? 1.0f / pmax : 0.0f;
    w = fi * inv;
  } else {
    total *= ratio;
    w = total * fi;
  }
}

template void PathTracer::trace_lanes<1>(const Ray&, Rng&, PathScratch&) const;
template void PathTracer::trace_lanes<0>(const Ray&, Rng&, PathScratch&) const;

}  // namespace prizma::render
