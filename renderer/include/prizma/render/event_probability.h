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

#include "prizma/spectral/bin_layout.h"

namespace prizma::render {

struct Material;

enum class EventProbabilities : unsigned char { Auto, Max, Average, Mixed, Implicit };

// "auto", "max", "average", "mixed", "implicit".
std::string event_probabilities_name(EventProbabilities e);
// The inverse; InputError(input, "must be one of ...") for any other name.
EventProbabilities parse_event_probabilities(std::string_view name, std::string_view input = "event_probabilities");

// What the auto rule measured in each material's spectra (bin averages) and what it chose.
struct MaterialEvents {
  EventProbabilities scheme = EventProbabilities::Max;
  double extinction_ratio = 1.0;  // max_i σt,i / min_i σt,i over the bins (1 = grey; ∞ when some σt,i = 0)
  double albedo_spread = 0.0;     // max_i α_i − min_i α_i over the bins (α = σs/σt)
  double albedo_max = 0.0;        // max_i α_i
};

// The auto rule (docs/renderer.md, "Event probabilities"), per material, since the scheme may change
// from one collision to the next without bias: "implicit", except in a material that absorbs more
// than it scatters in every bin (max_i α_i < kAbsorbingAlbedo), where implicit capture would walk
// the path through the whole absorber: "average" there. Deterministic: a function of the material's
// spectra and the bins only. `requested` other than Auto is given to every material as it is (the
// measurements still made).
inline constexpr double kAbsorbingAlbedo = 0.5;
MaterialEvents choose_event_probabilities(EventProbabilities requested, const Material& material,
                                          const spectral::BinLayout& bins);
std::vector<MaterialEvents> choose_event_probabilities(EventProbabilities requested,
                                                       const std::vector<Material>& materials,
                                                       const spectral::BinLayout& bins);
// "rayleigh average (extinction ratio 9.4, albedo spread 0), sphere max (1, 0.55)": for logs.
std::string describe_event_probabilities(const std::vector<MaterialEvents>& choice,
                                         const std::vector<Material>& materials);

// m_e for the three events of a collision (the tracer's inner loop; inline so that it vectorises
// with the loop that computes σ). Weights and coefficients are ≥ 0.
struct EventCoefficients {
  float absorb = 0.0f, scatter = 0.0f, null = 0.0f;
};

inline EventCoefficients event_coefficients(EventProbabilities scheme, int n, const float* __restrict w,
                                            const float* __restrict sa, const float* __restrict ss,
                                            const float* __restrict sn) {
  EventCoefficients mx, sum;
  if (scheme != EventProbabilities::Average)
    for (int i = 0; i < n; ++i) {
      mx.absorb = std::max(mx.absorb, w[i] * sa[i]);
      mx.scatter = std::max(mx.scatter, w[i] * ss[i]);
      mx.null = std::max(mx.null, w[i] * sn[i]);
    }
  if (scheme == EventProbabilities::Max || scheme == EventProbabilities::Auto) return mx;
  for (int i = 0; i < n; ++i) {
    sum.absorb += w[i] * sa[i];
    sum.scatter += w[i] * ss[i];
    sum.null += w[i] * sn[i];
  }
  if (scheme == EventProbabilities::Average) return sum;
  if (scheme == EventProbabilities::Implicit) {
    if (n > 1) sum.absorb = 0.0f;  // one lane: analog tracking (its weight must stay exactly 1)
    return sum;
  }
  const float k = 1.0f / static_cast<float>(n);
  return {mx.absorb + k * sum.absorb, mx.scatter + k * sum.scatter, mx.null + k * sum.null};
}

// m_e of one more event whose coefficient is d·x_i (fluorescence), by the same scheme.
inline float event_coefficient(EventProbabilities scheme, int n, const float* __restrict w, float d,
                               const float* __restrict x) {
  float mx = 0.0f, sum = 0.0f;
  for (int i = 0; i < n; ++i) {
    mx = std::max(mx, w[i] * d * x[i]);
    sum += w[i] * d * x[i];
  }
  switch (scheme) {
    case EventProbabilities::Average:
    case EventProbabilities::Implicit: return sum;
    case EventProbabilities::Mixed: return mx + sum / static_cast<float>(n);
    default: return mx;
  }
}

}  // namespace prizma::render
