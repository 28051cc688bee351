#include "prizma/render/fluorescence.h"

#include <algorithm>
#include <set>

#include "prizma/render/path_tracer.h"

namespace prizma::render {

double fluorescence_emission_area(const spectral::Spectrum& emission) {
  const double lo = std::max(360.0, emission.domain_lo_nm());
  const double hi = std::min(830.0, emission.domain_hi_nm());
  return hi > lo ? emission.integrate(lo, hi) : 0.0;
}

FluorescenceLayout fluorescence_layout(const Medium& medium, const spectral::BinLayout& bins) {
  FluorescenceLayout out;
  std::set<int> ins, outs;
  for (const Material& m : medium.materials) {
    if (!m.fluorescent || !(m.fluorescence.quantum_yield > 0.0)) continue;
    out.any = true;
    for (int i = 0; i < bins.size(); ++i) {
      if (spectrum_max_over(m.fluorescence.absorption, bins.lo_nm(i), bins.hi_nm(i)) > 0.0) ins.insert(i);
      if (spectrum_max_over(m.fluorescence.emission, bins.lo_nm(i), bins.hi_nm(i)) > 0.0) outs.insert(i);
    }
  }
  for (int in : ins)
    for (int o : outs) {
      if (in != o) out.pairs.push_back({in, o});
    }
  for (int in : ins)
    if (outs.count(in)) out.diagonal.push_back(in);
  return out;
}

}  // namespace prizma::render
