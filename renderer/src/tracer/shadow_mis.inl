// PathTracer, spectral MIS for shadow rays (WavelengthSampling::SpectralMis; docs/renderer.md,
// "Spectral MIS"): residual ratio tracking toward a light at the hero lane's own residual rate, every
// lane weighted by the balance heuristic over the lanes' techniques together with the path's (pbrt-v4's
// SampleLd with the rescaled path probabilities r_u, r_l; Miller, Georgiev and Jarosz 2019). Part of
// path_tracer.cpp's translation unit (see there).
//
// Lane i's residual transmittance R_i = e^{−∫ r_i}, r_i = σt,i − σc,i, is the integral over sets of
// points x_1..x_m of f_i = Π (μ̄_i(x) − r_i(x)) · e^{−∫ μ̄_i} for any rate μ̄_i; technique k draws them
// as a Poisson process of rate μ̄_k, density p_k = Π μ̄_k(x) · e^{−∫ μ̄_k}. In a cell whose control
// is material m, μ̄_k = μ̄r · σt_m,k / max_k' σt_m,k' (≥ (d_max − d_c)·σt_m,k, the cell's residual
// bound at lane k's own wavelength); elsewhere every lane has the cell's μ̄r. The path's hero j draws
// the points, and with the path's normalised densities ρ (spectral_mis.inl) lane i gets
//   T_i = e^{−∫ σc,i} · f_i / (Σ_k ρ_k p_k / Σ_k ρ_k),
// one-sample balance over the lanes for path and shadow ray together: W_i·T_i ≤ n × lane i's own
// (analog path, ratio-tracked) estimate. Only the ratios f_i/p_j and p_k/p_j are kept, renormalised
// at each point so that Σ ρ_k P_k stays Σ ρ_k.
#include "../path_tracer_internal.h"
#include "prizma/render/fast_exp.h"

namespace prizma::render {

// long on purpose: the depth runs, current cell and roulette are state its segment and collision callbacks share (as transmittance<>).
void PathTracer::transmittance_mis(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, ConstLanes<0> rho,
                                   int hero, Lanes<0> T, Rng& rng, PathScratch& s, double t_max) const {
  // (One function of ~100 lines, as transmittance<> and free_flight_mis: the depth runs, the current
  // cell and the roulette are state that the segment and collision callbacks share.)
  const int n = s.lanes, j = hero;
  MaterialCache& cache = s.cache;
  // T: f_i / p_j, renormalised; then the estimate.
  LaneArray<0> tau(n);    // the controls' ∫ σc,i
  LaneArray<0> P(n);      // p_k / p_j, renormalised
  LaneArray<0> rate(n);   // the lanes' rates μ̄_k in the current cell
  LaneArray<0> depth(n);  // ∫ μ̄_k since the last point
  LaneArray<0> ratio(n);  // e^{D_j − D_k}
  LaneArray<0> a(n), b(n);  // a point's factors on the contributions and the densities
  T = 1.0f;
  P = 1.0f;
  const Ray ray{origin, dir};
  double t_enter, t_exit;
  if (!intersect_box(ray, m_medium->bounds_min, m_medium->bounds_max, t_enter, t_exit)) return;
  t_exit = std::min(t_exit, t_max);
  if (!(t_exit > t_enter)) return;
  const float rho_total = partial::sum(rho, n);
  const std::int64_t step_limit = s.counters.shadow_steps + kMaxPathSteps;
  auto sigma_t_of = [&](std::uint16_t m) { return lanes_of<0>(std::as_const(cache.sigma_t), n, m); };

  // Runs of cells whose control is material m: the scalars Σ d_c·ℓ (into τ) and Σ (μ̄r/σt_hi)·ℓ (into
  // the lanes' rate depths D), put on the lanes × σt_m when the material changes or at a point.
  const CellControl* control = nullptr;
  std::uint16_t run_material = CellControl::kNone;
  float run_tau = 0.0f, run_depth = 0.0f, run_sigma_min = 0.0f, run_sigma_hi = 0.0f;
  bool any_tau = false, any_depth = false;
  float tau_min = 0.0f;
  auto flush = [&]() {
    if (run_material == CellControl::kNone) return;
    const ConstLanes<0> st = sigma_t_of(run_material);
    if (run_tau > 0.0f) {
      if (any_tau)
        tau += st * run_tau;
      else
        tau = st * run_tau;
      any_tau = true;
      tau_min = partial::min_from_infinity(tau, n);
    }
    if (run_depth > 0.0f) {
      if (any_depth)
        depth += st * run_depth;
      else
        depth = st * run_depth;
      any_depth = true;
    }
    run_tau = run_depth = 0.0f;
  };
  float cell_scale = 0.0f;  // μ̄r / σt_hi of the current cell (0: no per-lane rates)
  double cell_t1 = 0.0, t_from = 0.0;
  auto count_to = [&](double t) {
    if (cell_scale > 0.0f) run_depth += cell_scale * static_cast<float>(t - t_from);
    t_from = t;
  };
  // e^{D_j − D_k} into ratio (lane k's rate depth against the hero's since the last point).
  auto depth_ratios = [&]() {
    flush();
    if (any_depth)
      ratio = lane_map([](float x) { return exp_approx(x); }, depth[j] - depth);
    else
      ratio = 1.0f;
    any_depth = false;
  };
  // T_i ← T_i a_i / S, P_k ← P_k b_k / S with S = Σ ρ_k P_k b_k / Σ ρ_k; false: nothing is left.
  auto update = [&]() {
    const float mix = partial::sum(rho * P * b, n);
    if (!(mix > 0.0f) || !std::isfinite(mix)) {
      T = 0.0f;
      return false;
    }
    const float inv = rho_total / mix;
    mis_detail::scale_both(n, inv, T.data(), P.data(), a.data(), b.data());  // T, P, a, b: lanes of their own
    return true;
  };
  auto on_segment = [&](const MajorantTraversal::Segment& seg, float& mu) {
    count_to(cell_t1);
    cell_scale = 0.0f;
    if (!(seg.majorant > 0.0f)) return true;  // empty: no points, no depth
    control = &m_grid.control(seg.cell);
    const std::uint16_t m = control->material;
    if (m == CellControl::kNone) {  // every lane at the cell's μ̄: its depth is the same for all
      mu = control->residual;
      return true;
    }
    if (m != run_material) {
      flush();
      run_material = m;
      if (!cache.holds(m)) evaluate_material(m, s);
      run_sigma_min = partial::min_from_infinity(sigma_t_of(m), n);
      run_sigma_hi = partial::max_from_zero(sigma_t_of(m), n);
    }
    run_tau += control->density * static_cast<float>(seg.t1 - seg.t0);
    // Lane k's rate (d_max − d_c)·σt_m,k where the cell's spectral bound is of the control's material
    // (d_max ≥ d at every point, so (d − d_c)·σt_m,k ≤ it in float too: no factor below 0), else
    // μ̄r·σt_m,k / max_k' σt_m,k' (μ̄r bounds the residual at the render's largest σt_m).
    const CellSpectralBound bound = m_grid.spectral_bound(seg.cell);
    if (bound.material == m)
      cell_scale = std::max(0.0f, bound.density_max - control->density);
    else if (run_sigma_hi > 0.0f)
      cell_scale = control->residual / run_sigma_hi;
    mu = cell_scale * sigma_t_of(m)[j];  // 0: the hero takes no points here
    cell_t1 = seg.t1;
    t_from = seg.t0;
    return true;
  };
  const bool reached = sample_segments(m_grid, ray, t_enter, t_exit, rng, s.counters.majorant_cells, on_segment,
                                       [&](const TentativeCollision& tc) {
    if (++s.counters.shadow_steps > step_limit) {
      T = kAbandoned;
      return false;
    }
    count_to(tc.t);
    depth_ratios();
    const std::uint16_t mc = control->material;
    if (mc == CellControl::kNone)
      rate = control->residual;
    else
      rate = sigma_t_of(mc) * cell_scale;
    residual_at(tc.p, *control, a, s);  // r_i(x) into a
    a = ratio * lane_max(0.0f, rate - a);
    b = ratio * rate;
    if (!update()) return false;
    return transmittance_roulette(T, tau_min + run_tau * run_sigma_min, rng);
  });
  if (!reached) return;
  count_to(cell_t1);
  depth_ratios();
  a = ratio;
  b = ratio;
  if (!update()) return;
  if (any_tau) T *= lane_map([](float x) { return std::exp(-x); }, tau);
}

void PathTracer::estimate_transmittance_mis(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_max,
                                            const std::vector<float>& rho, int hero, Rng& rng, PathScratch& s) const {
  MaterialCache& cache = s.cache;
  std::copy(s.in.lambda_nm.begin(), s.in.lambda_nm.end(), cache.lambda_nm.begin());
  cache.new_wavelengths();
  const int n = s.lanes;
  transmittance_mis(origin, dir, ConstLanes<0>(rho.data(), n), hero, lanes_of<0>(s.work.transmittance, n), rng, s,
                    t_max);
}

void PathTracer::residual_at(const Eigen::Vector3d& p, const CellControl& control, Lanes<0> r, PathScratch& s) const {
  // r_i = σt,i(p) − σc,i: the medium at p less the cell's control (0 without one).
  const int n = s.lanes;
  std::uint16_t m;
  float d;
  lookup(p, m, d);
  const std::uint16_t mc = control.material;
  if (m == Medium::kEmpty || d <= 0.0f) {
    m = mc;
    d = 0.0f;
  }
  if (m != Medium::kEmpty && !s.cache.holds(m)) evaluate_material(m, s);
  if (mc != CellControl::kNone && m == mc) {  // (d − d_c)·σt_m
    r = lanes_of<0>(std::as_const(s.cache.sigma_t), n, m) * (d - control.density);
    return;
  }
  if (m == Medium::kEmpty)
    r = 0.0f;
  else
    r = lanes_of<0>(std::as_const(s.cache.sigma_t), n, m) * d;
  if (mc != CellControl::kNone) r = ConstLanes<0>(r) - lanes_of<0>(std::as_const(s.cache.sigma_t), n, mc) * control.density;
}

bool PathTracer::transmittance_roulette(Lanes<0> T, float depth_lo, Rng& rng) const {
  // Below kTransmittanceRrThreshold on a bound of the largest lane, T_max·e^{−depth_lo}, stop with
  // probability kTransmittanceRrStop (the survivors × 1/(1 − it)); false: stopped.
  const float t_max = T.max();
  if (!(t_max < kTransmittanceRrThreshold) &&
      (!(depth_lo > 0.0f) || !(t_max * std::exp(-depth_lo) < kTransmittanceRrThreshold)))
    return true;
  if (rng.uniform() < kTransmittanceRrStop) {
    T = 0.0f;
    return false;
  }
  T *= 1.0f / (1.0f - kTransmittanceRrStop);
  return true;
}

}  // namespace prizma::render
