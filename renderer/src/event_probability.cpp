#include "prizma/render/event_probability.h"

#include <cmath>
#include <iomanip>
#include <sstream>
#include <limits>

#include "prizma/render/scene.h"
#include "prizma/spectral/error.h"

namespace prizma::render {

std::string event_probabilities_name(EventProbabilities e) {
  switch (e) {
    case EventProbabilities::Auto: return "auto";
    case EventProbabilities::Max: return "max";
    case EventProbabilities::Average: return "average";
    case EventProbabilities::Mixed: return "mixed";
    case EventProbabilities::Implicit: return "implicit";
  }
  return "auto";
}

EventProbabilities parse_event_probabilities(std::string_view name, std::string_view input) {
  for (EventProbabilities e : {EventProbabilities::Auto, EventProbabilities::Max, EventProbabilities::Average,
                               EventProbabilities::Mixed, EventProbabilities::Implicit})
    if (name == event_probabilities_name(e)) return e;
  throw spectral::InputError(std::string(input), "must be \"auto\", \"max\", \"average\", \"mixed\" or \"implicit\" (got \"" +
                                                     std::string(name) + "\")");
}

MaterialEvents choose_event_probabilities(EventProbabilities requested, const Material& m,
                                          const spectral::BinLayout& bins) {
  MaterialEvents c;
  double st_lo = std::numeric_limits<double>::infinity(), st_hi = 0.0;
  double al_hi = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < bins.size(); ++i) {
    const double lo = bins.lo_nm(i), hi = bins.hi_nm(i), width = bins.width_nm(i);
    const double st = std::max(0.0, m.sigma_t_per_unit.integrate(lo, hi) / width);
    st_lo = std::min(st_lo, st);
    st_hi = std::max(st_hi, st);
    al_hi = std::max(al_hi, std::clamp(m.albedo.integrate(lo, hi) / width, 0.0, 1.0));
  }
  if (st_hi > 0.0) {  // else no extinction anywhere: no collisions to choose for
    c.albedo_max = al_hi;
    c.extinction_ratio = st_lo > 0.0 ? st_hi / st_lo : std::numeric_limits<double>::infinity();
  }
  if (requested != EventProbabilities::Auto) {
    c.scheme = requested;
    return c;
  }
  // implicit, or max where every bin absorbs more than it scatters (docs/renderer.md, "Event
  // probabilities": why, and the stress comparisons that once kept auto at max for every material).
  c.scheme = c.albedo_max < kAbsorbingAlbedo ? EventProbabilities::Max : EventProbabilities::Implicit;
  return c;
}

std::vector<MaterialEvents> choose_event_probabilities(EventProbabilities requested,
                                                       const std::vector<Material>& materials,
                                                       const spectral::BinLayout& bins) {
  std::vector<MaterialEvents> out;
  out.reserve(materials.size());
  for (const Material& m : materials) out.push_back(choose_event_probabilities(requested, m, bins));
  return out;
}

std::string describe_event_probabilities(const std::vector<MaterialEvents>& choice,
                                         const std::vector<Material>& materials) {
  std::ostringstream o;
  o << std::setprecision(3);
  for (std::size_t k = 0; k < choice.size() && k < materials.size(); ++k)
    o << (k ? ", " : "") << materials[k].name << ' ' << event_probabilities_name(choice[k].scheme)
      << " (albedo max " << choice[k].albedo_max << ", extinction ratio " << choice[k].extinction_ratio << ')';
  return o.str();
}

}  // namespace prizma::render
