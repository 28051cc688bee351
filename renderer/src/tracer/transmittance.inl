// PathTracer, transmittance along a segment: residual ratio tracking over the majorant sampler, every
// lane at once. Part of path_tracer.cpp's translation unit (see there).
#include "../path_tracer_internal.h"

namespace prizma::render {

// long on purpose: residual ratio tracking: the control runs, roulette and depth are state the segment and collision callbacks share.
template <int kLanes>
void PathTracer::transmittance(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, Lanes<kLanes> T,
                               Rng& rng, PathScratch& s, double t_max) const {
  // Residual ratio tracking (Novák, Georgiev, Hanika, Jarosz 2014) against the cells' controls,
  // every lane at once: T = exp(−∫ σc ds) · Π (1 − (σt − σc)/μ̄r) over tentative collisions at the
  // residual rate μ̄r, with Russian roulette at the steps once T is small. A cell without a
  // control (σc = 0, μ̄r = its majorant) is plain ratio tracking, T *= 1 − σt/μ̄; a homogeneous
  // cell (μ̄r = 0) takes no steps. The controls' optical depth τ is summed per lane and applied
  // once at the end.
  const int n = lane_count<kLanes>(s);
  LaneArray<kLanes> tau(n);  // the controls' optical depth (written by the first flush)
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
    tau_min = partial::min_from_infinity(tau.view(), n);
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
  if (any_control) T *= lane_map([](float x) { return std::exp(-x); }, tau);
}

void PathTracer::estimate_transmittance(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_max,
                                        Rng& rng, PathScratch& s) const {
  MaterialCache& cache = s.cache;
  std::copy(s.in.lambda_nm.begin(), s.in.lambda_nm.end(), cache.lambda_nm.begin());
  cache.new_wavelengths();
  if (s.lanes == 1)
    transmittance<1>(origin, dir, lanes_of<1>(s.work.transmittance, 1), rng, s, t_max);
  else
    transmittance<0>(origin, dir, lanes_of<0>(s.work.transmittance, s.lanes), rng, s, t_max);
}

}  // namespace prizma::render
