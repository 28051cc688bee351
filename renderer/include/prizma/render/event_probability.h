#pragma once
// Spectral tracking's collision event probabilities (Kutz, Habel, Li, Novák, SIGGRAPH 2017, the
// "history-aware" schemes; docs/renderer.md, "Event probabilities"). At a tentative collision of a
// path carrying n lanes with weights w_i, event e ∈ {absorption, scattering, null (, fluorescence)}
// of coefficients σ_e,i is chosen with probability P_e = m_e / Σ_e' m_e', m_e = R_i(w_i σ_e,i), and
// lane i's weight is multiplied by σ_e,i / (μ̄ P_e). Any R with m_e > 0 whenever some w_i σ_e,i > 0
// keeps every lane unbiased; the schemes differ in variance:
//   max      R = max_i           (the weights stay bounded by Σ_e m_e / μ̄; Kutz et al.'s default)
//   average  R = Σ_i             (the balance heuristic of one-sample MIS over the lanes' analog
//                                 trackers: Σ_i w_i is kept exactly, every w_i ≤ Σ_j w_j)
//   mixed    R = max_i + mean_i  (half of each)
//   implicit R = Σ_i for scattering and null events, and no absorption event (m_absorb = 0): absorption
//            never ends the path, it lowers each lane's weight by that lane's own σa ("implicit
//            capture"; the Russian roulette after scattering ends paths of low weight). Unbiased
//            because an absorbed path contributes nothing. In a pure absorber it is ratio tracking.
// With one lane every scheme is analog delta tracking and the weight stays 1.
#include <algorithm>
#include <string>
#include <string_view>
#include <vector>

#include "prizma/render/partial_reduce.h"
#include "prizma/spectral/bin_layout.h"

namespace prizma::render {

struct Material;

enum class EventProbabilities : unsigned char { Auto, Max, Average, Mixed, Implicit };

// "auto", "max", "average", "mixed", "implicit".
std::string event_probabilities_name(EventProbabilities e);
// The inverse; InputError(input, "must be one of ...") for any other name.
EventProbabilities parse_event_probabilities(std::string_view name, std::string_view input = "event_probabilities");

// What the two auto rules measure in a material's spectra (bin averages), and the event scheme
// chosen. Only what a rule decides by is measured: albedo_max decides the event scheme (below),
// extinction_ratio the wavelength sampling (resolve_wavelength_sampling, render.h). Both rules are
// written out once, in docs/renderer.md ("Event probabilities", "Which scenes take spectral MIS").
struct MaterialEvents {
  EventProbabilities scheme = EventProbabilities::Max;
  double albedo_max = 0.0;        // max_i α_i over the bins (α = σs/σt); 0 when the material has no extinction
  double extinction_ratio = 1.0;  // max_i σt,i / min_i σt,i over the bins (1 = grey or no extinction; ∞ when some σt,i = 0)
};

// The event-probability auto rule (docs/renderer.md, "Event probabilities"), per material:
// "implicit", or "max" where max_i α_i < kAbsorbingAlbedo. Deterministic: a function of the
// material's spectra and the bins only. `requested` other than Auto is given to every material as
// it is (the measurements still made: the wavelength-sampling rule reads extinction_ratio).
inline constexpr double kAbsorbingAlbedo = 0.5;
MaterialEvents choose_event_probabilities(EventProbabilities requested, const Material& material,
                                          const spectral::BinLayout& bins);
std::vector<MaterialEvents> choose_event_probabilities(EventProbabilities requested,
                                                       const std::vector<Material>& materials,
                                                       const spectral::BinLayout& bins);
// "rayleigh implicit (albedo max 0.99, extinction ratio 7.7), absorber max (albedo max 0.4,
// extinction ratio 1)": for logs (prizma-render -v), each material's scheme and both measures.
std::string describe_event_probabilities(const std::vector<MaterialEvents>& choice,
                                         const std::vector<Material>& materials);

// m_e for the three events of a collision. Weights and coefficients are ≥ 0.
struct EventCoefficients {
  float absorb = 0.0f, scatter = 0.0f, null = 0.0f;
};

namespace event_detail {

// w_i·d·x_i, as partial::max_from_zero and partial::sum read it.
struct WeightedLanes {
  const float* __restrict w;
  const float* __restrict x;
  float d;
  float operator[](int i) const { return w[i] * d * x[i]; }
};

// A scheme's m_e from the maximum and the sum of w_i·d·x_i over n lanes (d = 1 but for
// fluorescence; w·1 is exactly w), in partial results (partial_reduce.h: vectorised, the same bits
// at every SIMD level): the one place where the schemes are defined.
inline float scheme_coefficient(EventProbabilities scheme, int n, const float* __restrict w, const float* __restrict x,
                                float d = 1.0f) {
  switch (scheme) {
    case EventProbabilities::Average:
    case EventProbabilities::Implicit: return partial::sum(WeightedLanes{w, x, d}, n);
    case EventProbabilities::Mixed:
      return partial::max_from_zero(WeightedLanes{w, x, d}, n) +
             partial::sum(WeightedLanes{w, x, d}, n) / static_cast<float>(n);
    default:  // Max (and Auto, which a material never keeps)
      return partial::max_from_zero(WeightedLanes{w, x, d}, n);
  }
}

}  // namespace event_detail

// m_e from given per-lane weights and coefficients. Under `implicit` absorption is left to the
// weights (m_a = 0), except with one lane: analog tracking, whose weight must stay exactly 1.
inline EventCoefficients event_coefficients(EventProbabilities scheme, int n, const float* __restrict w,
                                            const float* __restrict sa, const float* __restrict ss,
                                            const float* __restrict sn) {
  using event_detail::scheme_coefficient;
  const bool implicit_absorption = scheme == EventProbabilities::Implicit && n > 1;
  return {implicit_absorption ? 0.0f : scheme_coefficient(scheme, n, w, sa), scheme_coefficient(scheme, n, w, ss),
          scheme_coefficient(scheme, n, w, sn)};
}

// A tentative collision at density d in a cell of majorant μ̄: lane i's coefficients
// σs,i = d·σt,i·α_i, σa,i = d·σt,i − σs,i and σn,i = max(0, μ̄ − d·σt,i) (σt and α per unit density,
// at the lane's wavelength). The formulas, once.
inline void collision_lane(float density, float mu, float sigma_t, float albedo, float& sa, float& ss, float& sn) {
  const float sig_t = density * sigma_t;
  ss = sig_t * albedo;
  sa = sig_t - ss;
  sn = std::max(0.0f, mu - sig_t);
}

// Every lane's coefficients into sa, ss, sn, and nothing else: a loop that vectorises (the
// reductions come after it).
inline void collision_lanes(int n, float density, float mu, const float* __restrict sigma_t,
                            const float* __restrict albedo, float* __restrict sa, float* __restrict ss,
                            float* __restrict sn) {
  for (int i = 0; i < n; ++i) collision_lane(density, mu, sigma_t[i], albedo[i], sa[i], ss[i], sn[i]);
}

// The coefficients into sa, ss, sn, then the scheme's m_e of them with the weights w.
inline EventCoefficients collision_coefficients(EventProbabilities scheme, int n, float density, float mu,
                                                const float* __restrict sigma_t, const float* __restrict albedo,
                                                const float* __restrict w, float* __restrict sa,
                                                float* __restrict ss, float* __restrict sn) {
  collision_lanes(n, density, mu, sigma_t, albedo, sa, ss, sn);
  return event_coefficients(scheme, n, w, sa, ss, sn);
}

// m_e of one more event whose coefficient is d·x_i (fluorescence), by the same scheme.
inline float event_coefficient(EventProbabilities scheme, int n, const float* __restrict w, float d,
                               const float* __restrict x) {
  return event_detail::scheme_coefficient(scheme, n, w, x, d);
}

}  // namespace prizma::render
