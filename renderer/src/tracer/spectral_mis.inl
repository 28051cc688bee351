// PathTracer, spectral MIS (WavelengthSampling::SpectralMis; docs/renderer.md, "Spectral MIS"): the
// path is sampled for one hero lane j (a stratified draw over the bins, set by the caller), free
// flights with that lane's own majorant and event probabilities, scatterings with its own phase
// lobe, and every lane i is weighted by the one-sample balance heuristic over the lanes,
//   W_i = f_i / Σ_k c_k p_k,   c_k = 1/n,
// f_i lane i's path contribution and p_k the density of the same path had lane k been the hero
// (Veach 1997, §9.2.4; pbrt-v4's volpath with its rescaled path probabilities r_u; Miller, Georgiev
// and Jarosz 2019 for the null-scattering path space with per-lane majorants). Part of
// path_tracer.cpp's translation unit (see there).
//
// State: w_i = W_i (what lights are scored with) and ρ_k = p_k / Σ_k' c_k' p_k' (the lanes'
// normalised path densities; Σ_k ρ_k stays n). An event whose factor is a_i on lane i's contribution
// and b_k on technique k's density (both up to one common factor) updates
//   S = Σ_k ρ_k b_k / Σ_k ρ_k,   w_i ← w_i a_i / S,   ρ_k ← ρ_k b_k / S.
// Bounded: W_i ≤ f_i / (c_i p_i) = n · f_i/p_i, n times lane i's own (analog) weight.
#include "../path_tracer_internal.h"
#include "prizma/render/fast_exp.h"

namespace prizma::render {

namespace mis_detail {

// Σ x[i] and Σ y[i] in one pass, each in partial::sum's order: the same bits as partial::sum(x, n)
// and partial::sum(y, n).
template <class X, class Y>
void sum2(const X& x, const Y& y, int n, float& sx, float& sy) {
  constexpr int kW = partial::kWidth;
  float px[kW] = {}, py[kW] = {};
  int i = 0;
  for (; i + kW <= n; i += kW)
    for (int k = 0; k < kW; ++k) {
      px[k] += x[i + k];
      py[k] += y[i + k];
    }
  for (int k = 0; i < n; ++i, ++k) {
    px[k] += x[i];
    py[k] += y[i];
  }
  sx = 0.0f;
  for (int k = 0; k < kW; ++k) sx += px[k];
  sy = 0.0f;
  for (int k = 0; k < kW; ++k) sy += py[k];
}

// collision_lanes (event_probability.h) with a majorant per lane, lane k's own μ̄_k. The pointers are
// __restrict so that GCC vectorises the loop: with six plain pointers it needs more alias checks than
// it versions a loop for, and the loop over Lanes views it replaces stayed scalar.
inline void collision_lanes_per_lane(int n, float density, const float* __restrict mu,
                                     const float* __restrict sigma_t, const float* __restrict albedo,
                                     float* __restrict sa, float* __restrict ss, float* __restrict sn) {
  for (int i = 0; i < n; ++i) collision_lane(density, mu[i], sigma_t[i], albedo[i], sa[i], ss[i], sn[i]);
}

// x[i] *= a[i]·inv and y[i] *= b[i]·inv in one pass (the same bits as the two products apart): the
// MIS update of the path's weights and densities, and of a shadow ray's T and P. x and y are rows
// of their own; a and b are only read (they may be one row).
inline void scale_both(int n, float inv, float* __restrict x, float* __restrict y, const float* __restrict a,
                       const float* __restrict b) {
  for (int i = 0; i < n; ++i) {
    x[i] *= a[i] * inv;
    y[i] *= b[i] * inv;
  }
}

// Implicit capture's density factors b_k = T_k μ̄_k P_e,k, with P_e,k = coef_k / (σs,k + σn,k) and
// `none` (1 for a scattering, 0 for a null event) where both are 0. Restrict pointers and a division by
// 1 where the sum is 0, so that GCC vectorises the loop.
inline void implicit_densities(int n, float none, const float* __restrict ratio, const float* __restrict mu,
                               const float* __restrict coef, const float* __restrict ss,
                               const float* __restrict sn, float* __restrict b) {
  for (int k = 0; k < n; ++k) {
    const float ck = ss[k] + sn[k];
    const float q = coef[k] / (ck > 0.0f ? ck : 1.0f);
    b[k] = ratio[k] * mu[k] * (ck > 0.0f ? q : none);
  }
}

}  // namespace mis_detail

bool PathTracer::mis_update(PathState<0>& v, ConstLanes<0> a, ConstLanes<0> b) const {
  const int n = v.n;
  LaneArray<0>& rho = v.rho;
  // Σ ρ and Σ ρ b in one pass, w and ρ in another (the same bits as two partial::sum calls and
  // `w *= a * inv; ρ *= b * inv`, in half the passes over the lanes). a and b are lanes of their own,
  // never w or ρ (they may be the same lanes as each other: both are only read).
  float total, mix;
  mis_detail::sum2(rho.view(), rho * b, n, total, mix);
  if (!(mix > 0.0f) || !(total > 0.0f) || !std::isfinite(mix)) return false;  // no lane can go on
  const float inv = total / mix;  // 1 / S
  mis_detail::scale_both(n, inv, v.w.data(), rho.data(), a.data(), b.data());
  return true;
}

// long on purpose: the depth runs and current cell are state its segment and collision callbacks share (the collision is collide_mis).
PathTracer::FlightEnd PathTracer::free_flight_mis(PathState<0>& v, Rng& rng, PathScratch& s) const {
  // Distances at the hero's majorant μ̄_j (per lane: d_max·σt_m(λ_k) in a cell with a spectral bound,
  // else the cell's μ̄ for every lane), events with the hero's probabilities: σe,j/μ̄_j (absorption an
  // event), or under `implicit` σe,j/(σs,j + σn,j) with absorption left to the weights. Technique k's
  // density of a tentative collision followed by event e is μ̄_k·T_k·P_e,k (T_k = e^{−∫ μ̄_k}); lane
  // i's contribution factor is T_i·σe,i. Only the ratios T_k/T_j enter the update, so only the depths
  // of cells with a spectral bound are summed: elsewhere every lane's majorant is the cell's, and
  // its depth is the same for all lanes. (One function of ~90 lines: the depth runs and the current
  // cell are state that the segment and collision callbacks share; the collision is collide_mis.)
  const int n = v.n, j = v.hero;
  MaterialCache& cache = s.cache;
  LaneArray<0> rate(n);   // μ̄_k of the current cell
  LaneArray<0> depth(n);  // ∫ μ̄_k over bound cells since the last collision
  LaneArray<0> ratio(n);  // T_k / T_j at a collision
  auto sigma_t_of = [&](std::uint16_t m) { return lanes_of<0>(std::as_const(cache.sigma_t), n, m); };

  // Runs of bound cells of one material m add up the scalar Σ d_max·ℓ, put on the lanes as that
  // × σt_m when the material changes or at a collision (one multiply-add per cell, not per lane).
  std::uint16_t run_material = CellSpectralBound::kNone;
  float run_depth = 0.0f;
  bool any_depth = false;  // depth holds a flushed run
  auto flush = [&]() {
    if (run_material != CellSpectralBound::kNone && run_depth > 0.0f) {
      if (any_depth)
        depth += sigma_t_of(run_material) * run_depth;
      else
        depth = sigma_t_of(run_material) * run_depth;
      any_depth = true;
    }
    run_depth = 0.0f;
  };
  CellSpectralBound cell;  // the current cell's bound
  bool in_cell = false;
  bool rate_set = false;  // rate holds the current cell's μ̄_k (set at its first collision)
  double cell_t1 = 0.0, t_from = 0.0;  // the cell's end; where its not yet counted part starts
  auto count_to = [&](double t) {
    if (in_cell && cell.material != CellSpectralBound::kNone) {
      if (cell.material != run_material) {
        flush();
        run_material = cell.material;
      }
      run_depth += cell.density_max * static_cast<float>(t - t_from);
    }
    t_from = t;
  };
  // T_k/T_j = e^{D_j − D_k} into ratio; the depths start again.
  auto transmittance_ratios = [&]() {
    flush();
    run_material = CellSpectralBound::kNone;
    if (any_depth) {
      const float dj = depth[j];
      ratio = lane_map([](float x) { return exp_approx(x); }, dj - depth);
    } else {
      ratio = 1.0f;
    }
    any_depth = false;
  };
  auto on_segment = [&](const MajorantTraversal::Segment& seg, float& mu) {
    count_to(cell_t1);
    in_cell = false;
    rate_set = false;
    if (!(seg.majorant > 0.0f)) return true;  // empty cell: no collisions, no depth in any lane
    cell = m_grid.spectral_bound(seg.cell);
    if (cell.material != CellSpectralBound::kNone) {
      if (!cache.holds(cell.material)) evaluate_material(cell.material, s);
      mu = cell.density_max * sigma_t_of(cell.material)[j];  // 0: the hero sees nothing here
    } else {
      mu = seg.majorant;
    }
    in_cell = true;
    cell_t1 = seg.t1;
    t_from = seg.t0;
    return true;
  };

  FlightEnd end = FlightEnd::Escaped;
  const Ray ray{v.pos, v.dir};
  const bool reached = sample_segments(m_grid, ray, v.t_enter, v.t_exit, rng, s.counters.majorant_cells, on_segment,
                                       [&](const TentativeCollision& tc) {
    if (++s.counters.collisions + s.counters.shadow_steps > v.step_limit) {
      end = FlightEnd::Abandoned;
      return false;
    }
    count_to(tc.t);
    transmittance_ratios();
    // The lanes' majorants, once per cell.
    if (!rate_set) {
      if (cell.material != CellSpectralBound::kNone)
        rate = sigma_t_of(cell.material) * cell.density_max;
      else
        rate = tc.mu;
      rate_set = true;
    }
    return collide_mis(v, tc, rate, ratio, end, rng, s);
  });
  if (!reached) return end;
  // Escaped: no collision up to the exit, density T_k for technique k, contribution T_i.
  count_to(cell_t1);
  transmittance_ratios();
  return mis_update(v, ratio, ratio) ? FlightEnd::Escaped : FlightEnd::Absorbed;
}

bool PathTracer::collide_mis(PathState<0>& v, const TentativeCollision& tc, ConstLanes<0> rate, ConstLanes<0> ratio,
                             FlightEnd& end, Rng& rng, PathScratch& s) const {
  // A tentative collision of the hero's free flight, with the transmittance ratios T_k/T_j since the
  // last one and the lanes' majorants μ̄_k of its cell (free_flight_mis's): the emission layer, then
  // the hero's event and every lane's update. True: a null collision, the walk goes on; false with
  // `end` Absorbed or Scattered (v.pos, v.material set).
  const int n = v.n, j = v.hero;
  MaterialCache& cache = s.cache;
  const LaneArray<0>& w = v.w;
  LaneArray<0> sa(n), ss(n), sn(n);  // σa, σs, σn at the lanes' own majorants
  LaneArray<0> b(n);                 // the event's factors on the densities
  std::uint16_t m;
  float d;
  lookup(tc.p, m, d);
  if (m == Medium::kEmpty || d <= 0.0f) {  // σt = 0: a null collision for every technique
    b = ratio * rate;
    if (!mis_update(v, b, b)) {
      end = FlightEnd::Absorbed;
      return false;
    }
    return true;
  }
  if (!cache.holds(m)) evaluate_material(m, s);
  // σn,k = μ̄_k − σt,k with the lane's own majorant
  mis_detail::collision_lanes_per_lane(n, d, rate.data(), cache.sigma_t.data() + static_cast<std::size_t>(m) * n,
                                       cache.albedo.data() + static_cast<std::size_t>(m) * n, sa.data(), ss.data(),
                                       sn.data());
  if (m_emits[m]) {
    // Emission at every tentative collision (pbrt-v4's estimator): lane i's ∫ T_i σa,i Le,i ds
    // sampled at density Σ_k c_k p_k μ̄_k T_k.
    const float total = partial::sum(v.rho, n), mix = partial::sum(v.rho * ratio * rate, n);
    if (mix > 0.0f)
      v.lanes(v.em) += w * ratio * sa * lanes_of<0>(std::as_const(cache.emission_le), n, m) * (total / mix);
  }
  const bool implicit = m_events[m] == EventProbabilities::Implicit;
  bool scatter;
  if (!implicit) {  // analog: a_i = b_i = T_i σe,i
    const float c = sa[j] + ss[j] + sn[j];
    const float xi = rng.uniform() * c;
    if (xi < sa[j]) {
      end = FlightEnd::Absorbed;
      return false;
    }
    scatter = xi < sa[j] + ss[j];
    b = ratio * (scatter ? ss : sn);
    if (!mis_update(v, b, b)) {
      end = FlightEnd::Absorbed;
      return false;
    }
  } else {
    // Implicit capture: P_s,k = σs,k/(σs,k + σn,k) (1 when both are 0), a_i = T_i σe,i,
    // b_k = T_k μ̄_k P_e,k; a_i / b_i = (σs,i + σn,i)/μ̄_i is lane i's survival.
    const float cj = ss[j] + sn[j];
    scatter = cj > 0.0f ? rng.uniform() * cj < ss[j] : true;
    LaneArray<0> a(n);  // the event's factors on the contributions
    const LaneArray<0>& coef = scatter ? ss : sn;
    a = ratio * coef;
    mis_detail::implicit_densities(n, scatter ? 1.0f : 0.0f, ratio.data(), rate.data(), coef.data(), ss.data(),
                                   sn.data(), b.data());
    if (!mis_update(v, a, b)) {
      end = FlightEnd::Absorbed;
      return false;
    }
  }
  if (!scatter) return true;
  v.pos = tc.p;
  v.material = m;
  v.isotropic = false;
  end = FlightEnd::Scattered;
  return false;
}

bool PathTracer::sample_phase_hero(PathState<0>& v, ConstLanes<0> g, bool g_constant, Rng& rng) const {
  // The hero's lobe: cos θ from p_j, then w_i ← w_i p_i / q and ρ_k ← ρ_k p_k / q with
  // q = Σ_k ρ_k p_k / Σ_k ρ_k, the density of the direction over the lanes' techniques given the
  // path so far (what escaping paths weigh environment maps' MIS with; estimate_lights the same).
  if (g_constant) return sample_phase(v, g, g_constant, rng);
  const int n = v.n;
  const float cos_theta = hg_sample_cos(g[v.hero], rng.uniform());
  LaneArray<0> f(n);
  f = lane_map([cos_theta](float gi) { return hg_phase(cos_theta, gi); }, g);
  const float total = partial::sum(v.rho, n), mix = partial::sum(v.rho * f, n);
  if (!mis_update(v, f, f)) return false;
  v.phase_pdf = mix / total;
  v.dir = direction_around(v.dir, cos_theta, rng.uniform_double()).normalized();
  return true;
}

}  // namespace prizma::render
