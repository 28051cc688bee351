#include "prizma/render/fluorescence.h"

#include <algorithm>
#include <cmath>
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

namespace prizma::render {

void PathResult::close_fluorescent_segment(float lambda_in_nm) {
  const bool saw = fl_environment[0] != 0.0f || fl_emission[0] != 0.0f ||
                   std::any_of(fl_directional.begin(), fl_directional.end(), [](float v) { return v != 0.0f; });
  if (saw) {
    fl_segments.push_back(lambda_in_nm);
    fl_segments.push_back(fl_environment[0]);
    fl_segments.push_back(fl_emission[0]);
    fl_segments.insert(fl_segments.end(), fl_directional.begin(), fl_directional.end());
  }
  fl_environment[0] = 0.0f;
  fl_emission[0] = 0.0f;
  std::fill(fl_directional.begin(), fl_directional.end(), 0.0f);
}

ExcitationSampler::ExcitationSampler(const spectral::Spectrum& sigma_f, double lo_nm, double hi_nm)
    : m_sigma_f(&sigma_f) {
  if (!(hi_nm > lo_nm)) return;
  // Cell edges: a grid of at most kCellNm and σf's own breakpoints (σf is linear between them).
  const int n = std::max(1, static_cast<int>(std::ceil((hi_nm - lo_nm) / kCellNm)));
  std::vector<double> edges;
  for (int i = 0; i <= n; ++i) edges.push_back(i == n ? hi_nm : lo_nm + (hi_nm - lo_nm) * i / n);
  for (double l : sigma_f.wavelengths_nm())
    if (l > lo_nm && l < hi_nm) edges.push_back(l);
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  m_edges_nm = edges;
  m_cdf.assign(edges.size(), 0.0);
  for (std::size_t k = 0; k + 1 < edges.size(); ++k) {
    // ∫_a^b (fa + (fb − fa)·t)·(a + (b − a)·t)·(b − a) dt with σf linear on the cell (clamped ≥ 0 at
    // the ends, as the tracer clamps it).
    const double a = edges[k], b = edges[k + 1], h = b - a;
    const double fa = std::max(0.0, sigma_f.eval(a)), fb = std::max(0.0, sigma_f.eval(b));
    const double cell = h * (fa * a + 0.5 * (fa * h + (fb - fa) * a) + (fb - fa) * h / 3.0);
    m_cdf[k + 1] = m_cdf[k] + std::max(0.0, cell);
  }
  m_total = m_cdf.back();
}

ExcitationSampler::Draw ExcitationSampler::sample(double u) const {
  Draw d;
  if (!(m_total > 0.0)) return d;
  const double target = u * m_total;
  // The cell whose cumulative range holds the target (cells of zero integral are never chosen).
  auto it = std::upper_bound(m_cdf.begin(), m_cdf.end(), target);
  std::size_t k = static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(it - m_cdf.begin() - 1, 0,
                                                                      static_cast<std::ptrdiff_t>(m_cdf.size()) - 2));
  while (k > 0 && !(m_cdf[k + 1] > m_cdf[k])) --k;
  const double cell = m_cdf[k + 1] - m_cdf[k];
  if (!(cell > 0.0)) return d;
  const double a = m_edges_nm[k], h = m_edges_nm[k + 1] - a;
  const double t = std::clamp((target - m_cdf[k]) / cell, 0.0, 1.0);
  d.lambda_nm = a + t * h;
  // pdf(λ) = cell / (Λ·h) inside the cell: weight = σf(λ)·λ·h / cell.
  d.weight = std::max(0.0, m_sigma_f->eval(d.lambda_nm)) * d.lambda_nm * h / cell;
  return d;
}

}  // namespace prizma::render
