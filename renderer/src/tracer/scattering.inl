// PathTracer, after a scattering: the new direction from the phase function (one-sample MIS over the
// lanes' lobes) and Russian roulette. Part of path_tracer.cpp's translation unit (see there).
#include "../path_tracer_internal.h"

namespace prizma::render {

template <int kLanes>
bool PathTracer::sample_phase(PathState<kLanes>& v, ConstLanes<kLanes> g, bool g_constant, Rng& rng) const {
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
  LaneArray<kLanes>& w = v.w;
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
    LaneArray<kLanes> f(n);
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

}  // namespace prizma::render
