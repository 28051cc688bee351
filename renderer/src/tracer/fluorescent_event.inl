// PathTracer, the fluorescent event: light absorbed at one wavelength re-emitted at another, the
// path's transport rank one from there on (docs/fluorescence.md). Part of path_tracer.cpp's
// translation unit (see there).
#include "../path_tracer_internal.h"

namespace prizma::render {

void PathTracer::fluoresce(int m, float density, float k, float* weights, Rng& rng, PathScratch& s) const {
  // The event's weight on the out side, a_i = w_i·d·Φ_i·c/(μ̄·mf) (the spectral-tracking factor of
  // the event), then the lanes carry λin with weights p_j. The path's transport is rank one from
  // here on: M[out][in] += a[out]·(what lane in sees). A later event keeps a and scales the lanes by
  // Σ_i a'_i (Φ and p are rank one too, so the state stays rank one however many events chain).
  // The in side gets wavelengths of its own, λ'_j = lo_j + u'·Δλ_j with a fresh u': with the out
  // side's jitter, E[f(λ_out)·g(λ_in)] over the shared u is not the product of the bin averages
  // (a bias of 30 % in the tests). Φ was evaluated with Λ at the old wavelengths; the estimate of
  // ∫ σf·λ·L̄ dλ must use the new ones, hence the factor Λ'/Λ (the event's probability may use any Λ).
  const int n = s.lanes;
  MaterialCache& cache = s.cache;
  PathResult& out = s.out;
  if (n == 1) {
    // One wavelength per path (--wavelength-sampling single): the path's wavelength becomes λin,
    // drawn with density σf(λ)·λ/Λ (ExcitationSampler; Φ holds Λ), its weight that draw's. The out
    // side keeps the first event's factor a = w·d·Φ·c/(μ̄·mf); a later event's factor scales the in
    // side. The in bin is read off the wavelength, so a later event first closes the segment seen at
    // the previous λin (PathResult::fl_segments): left open, it would be counted in the new λin's bin.
    float& w0 = weights[0];
    const float event = w0 * density * cache.fl_out[static_cast<std::size_t>(m)] * k;
    if (out.fl_active) out.close_fluorescent_segment(cache.lambda_nm[0]);
    const ExcitationSampler::Draw draw = m_fl_excitation[m].sample(rng.uniform_double());
    cache.lambda_nm[0] = static_cast<float>(draw.lambda_nm);
    cache.new_wavelengths();  // every material is evaluated anew at the new wavelength
    if (!out.fl_active) {
      out.fl_a[0] = event;
      std::fill(out.fl_environment.begin(), out.fl_environment.end(), 0.0f);
      std::fill(out.fl_emission.begin(), out.fl_emission.end(), 0.0f);
      std::fill(out.fl_directional.begin(), out.fl_directional.end(), 0.0f);
      out.fl_segments.clear();
      out.fl_active = true;
      w0 = static_cast<float>(draw.weight);
    } else {
      w0 = event * static_cast<float>(draw.weight);
    }
    return;
  }
  const Lanes<0> w(weights, n);
  const Lanes<0> a = lanes_of<0>(out.fl_a, n);
  const ConstLanes<0> fo = lanes_of<0>(std::as_const(cache.fl_out), n, m);
  const double old_sum = cache.fl_lambda_sum[m];
  float total = 0.0f;  // later events: Σ_i a'_i
  if (!out.fl_active)
    a = w * density * fo * k;
  else
    total = sum_over(w * density * fo * k, n);
  const double u = rng.uniform_double();
  for (int i = 0; i < n; ++i) cache.lambda_nm[i] = static_cast<float>(s.in.lo_nm[i] + u * s.in.width_nm[i]);
  cache.new_wavelengths();  // every material is evaluated anew at the new wavelengths
  evaluate_material(m, s);
  const auto ratio = static_cast<float>(old_sum > 0.0 ? cache.fl_lambda_sum[m] / old_sum : 0.0);
  const ConstLanes<0> fi = lanes_of<0>(std::as_const(cache.fl_in), n, m);
  const float pmax = fi.max();
  if (!out.fl_active) {
    // First event: the diagonal results so far stay; the in side starts empty. The lanes' largest
    // weight is made 1 (its scale moved to a) so that Russian roulette sees a unit path.
    a *= ratio * pmax;
    std::fill(out.fl_environment.begin(), out.fl_environment.end(), 0.0f);
    std::fill(out.fl_emission.begin(), out.fl_emission.end(), 0.0f);
    std::fill(out.fl_directional.begin(), out.fl_directional.end(), 0.0f);
    out.fl_active = true;
    const float inv = pmax > 0.0f ? 1.0f / pmax : 0.0f;
    w = fi * inv;
  } else {
    total *= ratio;
    w = total * fi;
  }
}

}  // namespace prizma::render
