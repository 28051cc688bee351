// PathTracer, free flight: delta tracking with spectral tracking's event probabilities over the
// majorant sampler, ending absorbed, scattered (or re-emitted by a fluorescent event) or escaped.
// Part of path_tracer.cpp's translation unit (see there).
#include "../path_tracer_internal.h"

namespace prizma::render {

template <int kLanes>
PathTracer::FlightEnd PathTracer::free_flight(PathState<kLanes>& v, Rng& rng, PathScratch& s) const {
  // Delta tracking with spectral tracking's event probabilities (Kutz et al. 2017, history-aware
  // schemes, event_probability.h): P_e ∝ m_e = R_i(w_i σ_e,i) for e ∈ {absorb, scatter, null}, and
  // each lane's weight multiplied by σ_e,i / (μ̄ P_e). With one lane this is analog delta tracking.
  const int n = v.n;
  LaneArray<kLanes>& w = v.w;
  LaneArray<kLanes> sa(n), ss(n), sn(n);  // σa, σs, σn at the current collision
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
      fluoresce(m, d, c / (mu * mf), w.data(), rng, s);
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

}  // namespace prizma::render
