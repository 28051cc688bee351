#include "prizma/render/path_tracer.h"

#include "path_tracer_internal.h"
#include "prizma/render/render.h"
// The tracer's parts, a file each (renderer/src/tracer/), compiled here as one translation unit: the
// AVX2 and AVX-512 levels below flatten trace_baseline with everything it calls, which the compiler
// can do only for code it sees in this unit (a part in a unit of its own would stay at the baseline
// instruction set and be called, not vectorised).
#include "tracer/material_cache.inl"
#include "tracer/medium_lookup.inl"
#include "tracer/path_state.inl"
#include "tracer/transmittance.inl"
#include "tracer/free_flight.inl"
#include "tracer/light_estimates.inl"
#include "tracer/scattering.inl"
#include "tracer/fluorescent_event.inl"
#include "tracer/spectral_mis.inl"
#include "tracer/shadow_mis.inl"
#include "tracer/guides.inl"

namespace prizma::render {

PathTracer::PathTracer(const Scene& scene, double lambda_lo_nm, double lambda_hi_nm, bool use_grid)
    : m_medium(&scene.medium), m_simd(default_simd_level()), m_max_bounces(scene.settings.max_bounces),
      m_mis(resolve_wavelength_sampling(scene) == WavelengthSampling::SpectralMis) {
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
  w.transmittance.assign(n, 0.0f);
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
    trace_lanes<1, false>(ray, rng, s);
  else if (m_mis)
    trace_lanes<0, true>(ray, rng, s);
  else
    trace_lanes<0, false>(ray, rng, s);
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
template <int kLanes, bool kMis>
void PathTracer::trace_lanes(const Ray& camera_ray, Rng& rng, PathScratch& s) const {
  const int n = lane_count<kLanes>(s);
  MaterialCache& cache = s.cache;
  std::copy(s.in.lambda_nm.begin(), s.in.lambda_nm.end(), cache.lambda_nm.begin());
  cache.new_wavelengths();
  PathResult& out = s.out;
  PathState<kLanes> v(n);
  v.env = out.environment.data();
  v.em = out.emission.data();
  v.dir_out = out.directional.data();
  v.pos = camera_ray.origin;
  v.dir = camera_ray.direction;
  v.w = 1.0f;
  if constexpr (kMis) {
    v.rho = 1.0f;
    v.hero = s.in.hero_lane;
  }
  v.lanes(v.env) = 0.0f;
  v.lanes(v.em) = 0.0f;
  std::fill(out.directional.begin(), out.directional.end(), 0.0f);
  out.fl_active = false;
  begin_guides(out);

  if (!intersect_box(camera_ray, m_medium->bounds_min, m_medium->bounds_max, v.t_enter, v.t_exit)) {
    v.lanes(v.env) = 1.0f;
    add_escape(v.dir, 0.0, v.w.data(), v.dir_out, s);
    return;
  }
  ++s.counters.paths_in_volume;
  int bounces = 0;
  v.step_limit = s.counters.collisions + s.counters.shadow_steps + kMaxPathSteps;
  for (;;) {
    FlightEnd flight;
    if constexpr (kMis)
      flight = free_flight_mis(v, rng, s);
    else
      flight = free_flight(v, rng, s);
    switch (flight) {
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
        if (bounces == 0) record_first_scattering(v.pos, v.t_enter, camera_ray, *m_medium, out);
        break;
    }
    if (m_max_bounces >= 0 && bounces >= m_max_bounces) return;
    ++bounces;

    const ConstLanes<kLanes> g = v.isotropic ? lanes_of<kLanes>(std::as_const(s.work.zero_g), n)
                                             : lanes_of<kLanes>(std::as_const(cache.g), n, v.material);
    const bool g_constant = kLanes == 1 || v.isotropic || m_g_constant[v.material];
    estimate_lights(v, g, g_constant, rng, s);
    if constexpr (kMis) {
      if (!sample_phase_hero(v, g, g_constant, rng)) return;
    } else {
      if (!sample_phase(v, g, g_constant, rng)) return;
    }
    if (!roulette(v, rng)) return;
    if (!intersect_box(Ray{v.pos, v.dir}, m_medium->bounds_min, m_medium->bounds_max, v.t_enter, v.t_exit)) {
      v.lanes(v.env) += v.w;
      add_escape(v.dir, v.phase_pdf, v.w.data(), v.dir_out, s);
      return;
    }
  }
}
template void PathTracer::trace_lanes<1, false>(const Ray&, Rng&, PathScratch&) const;
template void PathTracer::trace_lanes<0, false>(const Ray&, Rng&, PathScratch&) const;
template void PathTracer::trace_lanes<0, true>(const Ray&, Rng&, PathScratch&) const;

}  // namespace prizma::render
