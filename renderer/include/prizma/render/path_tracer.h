#pragma once
// PathTracer: one path of the spectral volume path tracer (docs/renderer.md). A path carries n
// "lanes", each a wavelength with its own weight: all bins (spectral tracking, Kutz et al. 2017,
// max scheme), or one lane (a wavelength-independent medium traced once for all bins, or VPT's
// one-wavelength method). It returns, per lane, the radiance reaching the camera from the uniform
// unit environment, from each directional light of unit irradiance (unit white spectra), and the
// radiance the medium emits (the emission light).
#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "prizma/render/camera.h"
#include "prizma/render/fluorescence.h"
#include "prizma/render/light_sampler.h"
#include "prizma/render/majorant_grid.h"
#include "prizma/render/rng.h"
#include "prizma/render/scene.h"
#include "prizma/render/simd_level.h"

namespace prizma::render {

template <int kN>
class ConstLanes;  // renderer/src/lanes.h
template <int kN>
class Lanes;
struct TentativeCollision;  // renderer/src/majorant_sampler.h

// Counters a path adds to (summed per thread, then over threads).
struct PathCounters {
  std::int64_t paths_in_volume = 0;
  std::int64_t collisions = 0;
  std::int64_t shadow_steps = 0;
  std::int64_t majorant_cells = 0;
};

// Per-thread working memory of the tracer, sized once by PathTracer::prepare for n lanes and the
// scene's materials, in four parts: what the caller sets (in), what the tracer caches per path
// (cache), a few per-lane arrays (work) and what a path returns (out); plus counters. A path's own
// per-lane state (weights, densities, transmittances) is not here: it is LaneArray values
// (renderer/src/lanes.h) on the stack.
struct PathInputs {
  std::vector<float> lambda_nm;  // [lanes] the path's wavelengths, set before every trace()
  // Fluorescence (docs/fluorescence.md; used only when a material fluoresces): each lane's bin,
  // set once. A fluorescent event draws the lanes' wavelengths anew, lo + u'·width; width 0 = the
  // lane takes no part in fluorescence.
  std::vector<float> lo_nm;     // [lanes]
  std::vector<float> width_nm;  // [lanes]
  // Spectral MIS (WavelengthSampling::SpectralMis): the lane the path is sampled for, set before
  // every trace() (WavelengthMap::draw's hero: a stratified draw over the bins).
  int hero_lane = 0;
};

// The materials' spectra at the path's current wavelengths, evaluated the first time the path
// meets each material (stamped with the path id), so a collision costs a lookup and a few multiplies.
struct MaterialCache {
  std::vector<float> lambda_nm;    // [lanes] the wavelengths the cache holds: the inputs', then
                                   // after a fluorescent event the last segment's
  std::vector<float> sigma_t;      // [material][lanes] per unit density
  std::vector<float> albedo;       // [material][lanes]
  std::vector<float> g;            // [material][lanes]
  std::vector<float> emission_le;  // [material][lanes] emitted radiance at density 1 (emitting materials)
  std::vector<std::uint32_t> stamp;  // [material] path id that last evaluated it
  std::uint32_t path_id = 0;
  // The wavelengths changed (a new path, or a fluorescent event): every material is evaluated anew
  // when next met. A new id, and on the id's wrap-around every stamp forgotten.
  void new_wavelengths() {
    if (++path_id == 0) {
      std::fill(stamp.begin(), stamp.end(), 0u);
      path_id = 1;
    }
  }
  bool holds(std::size_t material) const { return stamp[material] == path_id; }
  // Fluorescent materials (see PathTracer::evaluate_fluorescence).
  std::vector<double> fl_lambda_sum;  // [material] Λ = Σ_j Δj·σf(λj)·λj
  std::vector<float> fl_out;          // [material][lanes] Φ_i = q·ρ(λi)/λi·Λ per unit density
  std::vector<float> fl_in;           // [material][lanes] p_j = Δj·σf(λj)·λj / Λ
};

// What the tracer keeps per thread besides the cache and the results (a path's own per-lane state,
// its weights, densities and a shadow ray's transmittance, lives in LaneArray values on the stack).
struct PathWork {
  std::vector<float> transmittance;  // [lanes] estimate_transmittance(_mis)'s result
  std::vector<float> zero_g;         // [lanes] g = 0: fluorescence's isotropic re-emission
};

// What trace() returns per lane (overwritten by every path): radiance at unit white.
struct PathResult {
  std::vector<float> environment;  // [lanes] from the unit environment
  std::vector<float> directional;  // [light with its own layer: directional_lights()][lanes]
  std::vector<float> emission;     // [lanes] emitted by the medium (the emission light)
  // A path that fluoresced (fl_active): its transport is rank one, M[out][in] += fl_a[out]·fl_<light>[in],
  // on top of the diagonal results above (the part before the first event). Sized only when a
  // material fluoresces.
  bool fl_active = false;
  std::vector<float> fl_a;            // [lanes] out side
  std::vector<float> fl_environment;  // [lanes] in side, per light as the diagonal results
  std::vector<float> fl_directional;  // [directional light][lanes]
  std::vector<float> fl_emission;     // [lanes]
  // One lane (--wavelength-sampling single) only: the in side of the segments that a later event
  // closed. A one-lane path's bin on the in side is that of its current wavelength λin, which every
  // event draws anew, so what it saw between two events belongs to the earlier λin: the later event
  // moves it here as one record of fl_segment_size(lights) floats, {λin, environment, emission,
  // directional[0..lights)}, and fl_<light> restart at zero (docs/fluorescence.md).
  std::vector<float> fl_segments;
  // Guide data (light-independent; prizma-render --features): whether the path scattered at all and
  // the distance from the volume's bounds to its first scattering along the camera ray.
  bool scattered = false;
  float first_scatter_depth = 0.0f;
  static constexpr std::size_t kSegmentLambda = 0, kSegmentEnvironment = 1, kSegmentEmission = 2,
                               kSegmentDirectional = 3;
  static std::size_t fl_segment_size(std::size_t directional_lights) { return kSegmentDirectional + directional_lights; }
  // One lane: closes the segment seen at lambda_in_nm (a record in fl_segments, none when it saw
  // nothing) and restarts fl_<light> at zero (renderer/src/fluorescence.cpp).
  void close_fluorescent_segment(float lambda_in_nm);
};

struct PathScratch {
  int lanes = 0;
  PathInputs in;
  MaterialCache cache;
  PathWork work;
  PathResult out;
  PathCounters counters;
};

class PathTracer {
 public:
  // Precomputes the material extinction bounds over [lambda_lo_nm, lambda_hi_nm], the majorant
  // grid (one cell when use_grid is false) and the light samplers.
  PathTracer(const Scene& scene, double lambda_lo_nm, double lambda_hi_nm, bool use_grid);

  // Sizes scratch for `lanes` lanes.
  void prepare(PathScratch& scratch, int lanes) const;
  // Traces the path of a camera ray at the wavelengths in scratch.in.lambda_nm (set by the caller).
  // Results in scratch.out (overwritten), the same bits at every SIMD level.
  void trace(const Ray& ray, Rng& rng, PathScratch& scratch) const;
  // The instruction set trace() runs on: default_simd_level() when built. set_simd_level throws
  // InputError("simd", …) for a level this CPU does not support (supported_simd_levels()).
  SimdLevel simd_level() const { return m_simd; }
  void set_simd_level(SimdLevel level);

  // Lights with their own result in scratch.directional (directional, point, sphere, spot and
  // environment-map lights; not the uniform environment nor emission), in scene order: their
  // indices in scene.lights.
  const std::vector<int>& directional_lights() const { return m_directional_index; }
  // The transmittance estimate next-event estimation uses (residual ratio tracking), from origin
  // along dir up to t_max at the wavelengths in scratch.in.lambda_nm, per lane into
  // scratch.work.transmittance (for tests and benches).
  void estimate_transmittance(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_max, Rng& rng,
                              PathScratch& scratch) const;
  // The same under spectral MIS (renderer/src/tracer/shadow_mis.inl): the points drawn at lane
  // `hero`'s own residual rates, every lane weighted by the balance heuristic over the lanes with
  // the path's normalised densities rho (lanes values, summing to lanes; all 1 at a path's start).
  void estimate_transmittance_mis(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_max,
                                  const std::vector<float>& rho, int hero, Rng& rng, PathScratch& s) const;
  const MajorantGrid& grid() const { return m_grid; }
  // Index in scene.lights of the emission light (Light::emission), or −1.
  int emission_light() const { return m_emission_light; }
  // The medium at a point inside the box: material index (kEmpty for empty space) and density, by
  // the medium's interpolation (nearest voxel, or the trilinear value classified by the rules).
  void lookup(const Eigen::Vector3d& p, std::uint16_t& material, float& density) const;
  // True when every material's spectra are constant: one lane serves all bins.
  bool wavelength_independent() const { return m_wavelength_independent; }
  // True when some material fluoresces (the path then may move weight between lanes).
  bool any_fluorescence() const { return m_any_fluorescence; }

 private:
  // How a free flight ends.
  enum class FlightEnd { Scattered, Escaped, Absorbed, Abandoned };
  template <int kLanes>
  struct PathState;

  // trace() compiled for each SimdLevel: the whole path (everything it inlines) at that level.
  void trace_baseline(const Ray& ray, Rng& rng, PathScratch& s) const;
  void trace_avx2(const Ray& ray, Rng& rng, PathScratch& s) const;
  void trace_avx512(const Ray& ray, Rng& rng, PathScratch& s) const;
  // One path, the way pbrt-v4's volpath reads: free flight (→ absorbed / scattered / escaped),
  // light estimates, phase sampling, roulette.
  // kMis: spectral MIS (one hero lane per path, renderer/src/tracer/spectral_mis.inl), else spectral
  // tracking (every lane steering the path through the event probabilities).
  template <int kLanes, bool kMis>
  void trace_lanes(const Ray& ray, Rng& rng, PathScratch& s) const;
  template <int kLanes>
  FlightEnd free_flight(PathState<kLanes>& v, Rng& rng, PathScratch& s) const;
  // Spectral MIS: the hero's free flight, its phase lobe, and the update of the lanes' weights and
  // densities by an event's factors a (contributions) and b (densities); false when nothing is left.
  FlightEnd free_flight_mis(PathState<0>& v, Rng& rng, PathScratch& s) const;
  // (rate: the lanes' majorants μ̄_k of the collision's cell, ratio: the transmittance ratios T_k/T_j.)
  bool collide_mis(PathState<0>& v, const TentativeCollision& tc, ConstLanes<0> rate, ConstLanes<0> ratio,
                   FlightEnd& end, Rng& rng, PathScratch& s) const;
  bool sample_phase_hero(PathState<0>& v, ConstLanes<0> g, bool g_constant, Rng& rng) const;
  bool mis_update(PathState<0>& v, ConstLanes<0> a, ConstLanes<0> b) const;
  template <int kLanes>
  void estimate_lights(PathState<kLanes>& v, ConstLanes<kLanes> g, bool g_constant, Rng& rng, PathScratch& s) const;
  template <int kLanes>
  bool sample_phase(PathState<kLanes>& v, ConstLanes<kLanes> g, bool g_constant, Rng& rng) const;
  template <int kLanes>
  bool roulette(PathState<kLanes>& v, Rng& rng) const;
  // Transmittance from origin along dir up to t_max, per lane, into T.
  template <int kLanes>
  void transmittance(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, Lanes<kLanes> T, Rng& rng,
                     PathScratch& s, double t_max = std::numeric_limits<double>::infinity()) const;
  // Spectral MIS's: residual ratio tracking at the hero lane's own rates, every lane weighted by the
  // balance heuristic over the lanes with the path's normalised densities rho (shadow_mis.inl).
  void transmittance_mis(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, ConstLanes<0> rho, int hero,
                         Lanes<0> T, Rng& rng, PathScratch& s, double t_max) const;
  // σt,i(p) − σc,i per lane into r: the medium at p less the cell's control.
  void residual_at(const Eigen::Vector3d& p, const CellControl& control, Lanes<0> r, PathScratch& s) const;
  // Ratio tracking's Russian roulette on T with depth_lo a lower bound of the depth still to apply;
  // false: stopped (T = 0).
  bool transmittance_roulette(Lanes<0> T, float depth_lo, Rng& rng) const;
  // A path leaving the medium along dir: the environment maps' radiance, MIS-weighted against NEE
  // by the density phase_pdf its direction was drawn with (0 = a camera ray), times the weights,
  // added to lights_out (the light layers: s.out.directional, or after a fluorescent event the in
  // side of the re-radiation term, s.out.fl_directional).
  void add_escape(const Eigen::Vector3d& dir, double phase_pdf, const float* w, float* lights_out,
                  PathScratch& s) const;
  void evaluate_material(int m, PathScratch& s) const;
  void evaluate_fluorescence(int m, PathScratch& s) const;
  // The fluorescent event at material m (w: the path's weights, s.lanes of them, changed in place).
  void fluoresce(int m, float density, float k, float* w, Rng& rng, PathScratch& s) const;
  // Trilinear: the raw value at p (NaN when a contributing voxel is not finite), and its class.
  float interpolate(const Eigen::Vector3d& p) const;
  void classify(float value, std::uint16_t& material, float& density) const;

  const Medium* m_medium;
  SimdLevel m_simd = SimdLevel::Baseline;
  MajorantGrid m_grid;
  Eigen::Vector3d m_inv_voxel;
  std::vector<LightSampler> m_lights;
  std::vector<int> m_escape_lights;  // indices in m_lights of the environment maps
  bool m_any_mis = false;            // some light's NEE is MIS-weighted against phase sampling
  std::vector<int> m_directional_index;
  std::vector<char> m_g_constant;  // per material
  std::vector<char> m_emits;       // per material: emission > 0 somewhere
  std::vector<char> m_fluorescent;  // per material: fluoresces with q > 0
  std::vector<spectral::Spectrum> m_fl_emission;  // per material: emission normalised to unit area
  std::vector<ExcitationSampler> m_fl_excitation;  // per material: λin of a one-lane path's event
  bool m_any_fluorescence = false;
  bool m_any_emission = false;
  int m_emission_light = -1;
  bool m_trilinear = false;
  int m_max_bounces = -1;
  bool m_wavelength_independent = false;
  bool m_mis = false;  // settings.wavelength_sampling is SpectralMis: trace() with several lanes takes it
  std::vector<EventProbabilities> m_events;  // per material: spectral tracking's scheme (event_probability.h)
};

// Largest value of a piecewise-linear spectrum over [lo_nm, hi_nm] (at the ends and the table's
// breakpoints inside).
double spectrum_max_over(const spectral::Spectrum& s, double lo_nm, double hi_nm);

}  // namespace prizma::render
