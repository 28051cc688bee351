// PathTracer, the light estimates: next-event estimation of every light at a scattering, and what an
// escaping path sees of the lights. Part of path_tracer.cpp's translation unit (see there).
#include "../path_tracer_internal.h"

namespace prizma::render {

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
void PathTracer::estimate_lights(PathState<kLanes>& v, ConstLanes<kLanes> g, bool g_constant, Rng& rng,
                                 PathScratch& s) const {
  // Next-event estimation of every light with its own layer (LightSampler: a direction toward the
  // light and its radiance / density), transmittance by ratio tracking up to the light (the box's
  // exit for distant lights). Environment maps weight the sample by the power heuristic against
  // the density q(ω) the phase sampling draws ω with (q = Σ_j m_j p_j / Σ_j m_j when g varies
  // across lanes, m = v.mix: the weights w under spectral tracking, the lanes' densities ρ under
  // spectral MIS); their escaping paths carry the complementary weight.
  const int n = v.n;
  const LaneArray<kLanes>& w = v.w;
  LaneArray<kLanes> f(n), T(n);  // the lanes' phase functions toward the light; the shadow ray's transmittance
  for (std::size_t l = 0; l < m_lights.size(); ++l) {
    LightSample ls;
    if (!m_lights[l].sample(v.pos, rng, ls)) continue;
    const Eigen::Vector3d& wl = ls.direction;
    const auto cos_theta = static_cast<float>(v.dir.dot(wl));
    if constexpr (kLanes == 0) {
      if (v.hero >= 0)  // spectral MIS: the shadow ray at the hero's rates (shadow_mis.inl)
        transmittance_mis(v.pos, wl, v.rho, v.hero, T, rng, s, ls.distance);
      else
        transmittance<kLanes>(v.pos, wl, T, rng, s, ls.distance);
    } else {
      transmittance<kLanes>(v.pos, wl, T, rng, s, ls.distance);
    }
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
        const ConstLanes<kLanes> m = v.mix();
        const float total = m.sum(), mix = sum_over(m * f, n);
        k *= total > 0.0f ? power_heuristic(ls.pdf, mix / total) : 0.0;
      }
      const auto kf = static_cast<float>(std::min(k, kFloatMax));
      out += w * kf * f * T;
    }
  }
}

}  // namespace prizma::render
