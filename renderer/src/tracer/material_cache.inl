// PathTracer, the material cache: each material's spectra evaluated at the path's wavelengths the
// first time the path meets it (and anew after a fluorescent event), so that a collision costs a
// voxel lookup and a few multiplies. Part of path_tracer.cpp's translation unit (see there).
#include "../path_tracer_internal.h"

namespace prizma::render {

namespace {

// Calls put(i, s.eval(λ_i)) for each lane's wavelength λ_i (float, as the cache holds them), with
// the values Spectrum::eval returns (the same table interval, the same interpolation expression),
// without a binary search per lane: the interval is guessed as if the table were evenly spaced
// (CSV tables usually are: 1 nm) and corrected by steps until it is std::upper_bound's, which it
// then is for any increasing table. The binary searches were a fifth of a path's time on
// data/scenes/bench_peer.json.
template <class Put>
void eval_lanes(const spectral::Spectrum& s, const float* lambda_nm, int n, Put&& put) {
  if (s.is_constant()) {
    const double c = s.eval(0.0);
    for (int i = 0; i < n; ++i) put(i, c);
    return;
  }
  const std::vector<double>& x = s.wavelengths_nm();
  const std::vector<double>& y = s.values();
  const std::size_t m = x.size();
  const double per_nm = m >= 2 ? static_cast<double>(m - 1) / (x.back() - x.front()) : 0.0;
  for (int i = 0; i < n; ++i) {
    const double l = lambda_nm[i];
    if (m < 2 || !(l >= x.front() && l <= x.back())) {
      put(i, 0.0);
      continue;
    }
    // j: the first entry > l (x[j − 1] ≤ l < x[j]; j = m when l is the last entry).
    auto j = static_cast<std::size_t>((l - x.front()) * per_nm) + 1;
    j = std::min(j, m);
    while (j < m && !(l < x[j])) ++j;
    while (j > 1 && l < x[j - 1]) --j;
    if (j >= m) {
      put(i, y.back());
      continue;
    }
    const std::size_t k = j - 1;
    const double t = (l - x[k]) / (x[k + 1] - x[k]);
    put(i, y[k] + t * (y[k + 1] - y[k]));
  }
}

}  // namespace

double spectrum_max_over(const spectral::Spectrum& s, double lo_nm, double hi_nm) {
  double m = std::max(s.eval(lo_nm), s.eval(hi_nm));
  for (std::size_t k = 0; k < s.wavelengths_nm().size(); ++k) {
    const double l = s.wavelengths_nm()[k];
    if (l >= lo_nm && l <= hi_nm) m = std::max(m, s.values()[k]);
  }
  return m;
}
void PathTracer::evaluate_material(int m, PathScratch& s) const {
  // Once per path and material: the spectra at the path's wavelengths, so that a collision costs a
  // voxel lookup and a few multiplies.
  const Material& mat = m_medium->materials[m];
  const int n = s.lanes;
  float* st = s.cache.sigma_t.data() + static_cast<std::size_t>(m) * n;
  float* al = s.cache.albedo.data() + static_cast<std::size_t>(m) * n;
  float* g = s.cache.g.data() + static_cast<std::size_t>(m) * n;
  float* le = s.cache.emission_le.data() + static_cast<std::size_t>(m) * n;
  const float* lambda = s.cache.lambda_nm.data();
  eval_lanes(mat.sigma_t_per_unit, lambda, n, [st](int i, double v) { st[i] = static_cast<float>(std::max(0.0, v)); });
  eval_lanes(mat.albedo, lambda, n, [al](int i, double v) { al[i] = static_cast<float>(std::clamp(v, 0.0, 1.0)); });
  eval_lanes(mat.anisotropy, lambda, n,
             [g](int i, double v) { g[i] = static_cast<float>(std::clamp(v, -0.9999, 0.9999)); });
  if (m_emits[m])
    eval_lanes(mat.emission, lambda, n, [le](int i, double v) { le[i] = static_cast<float>(std::max(0.0, v)); });
  if (mat.fluorescent) evaluate_fluorescence(m, s);
  s.cache.stamp[m] = s.cache.path_id;
}

void PathTracer::evaluate_fluorescence(int m, PathScratch& s) const {
  // σf joins the extinction (the albedo rescaled so that σs stays albedo·σt), and the two sides of
  // the event. Energy radiance: a photon absorbed at λin carries hc/λin, one re-emitted at λout
  // hc/λout, so the source at λout is q·ρ(λout)·∫ σf(λin)·(λin/λout)·L̄(λin) dλin (ρ the normalised
  // emission, L̄ the radiance averaged over directions). Over the path's jittered lanes
  // ∫ σf·λ·L̄ dλ ≈ Σ_j Δj·σf(λj)·λj·L̄(λj) (unbiased per bin), so the source at lane i is
  // Φ_i·Σ_j p_j·L̄(λj) with Φ_i = q·ρ(λi)/λi·Λ, p_j = Δj·σf(λj)·λj/Λ and Λ = Σ_j Δj·σf(λj)·λj.
  const Material& mat = m_medium->materials[m];
  const int n = s.lanes;
  float* st = s.cache.sigma_t.data() + static_cast<std::size_t>(m) * n;
  float* al = s.cache.albedo.data() + static_cast<std::size_t>(m) * n;
  float* fo = s.cache.fl_out.data() + static_cast<std::size_t>(m) * n;
  float* fi = s.cache.fl_in.data() + static_cast<std::size_t>(m) * n;
  double big_lambda = 0.0;
  for (int i = 0; i < n; ++i) {
    const double l = s.cache.lambda_nm[i];
    const auto sf = static_cast<float>(std::max(0.0, mat.fluorescence.absorption.eval(l)));
    const float st0 = st[i];
    st[i] = st0 + sf;
    al[i] = st[i] > 0.0f ? al[i] * (st0 / st[i]) : 0.0f;
    fi[i] = static_cast<float>(static_cast<double>(s.in.width_nm[i]) * sf * l);
    big_lambda += fi[i];
  }
  // One lane (--wavelength-sampling single): λin is drawn over the whole range, Λ = ∫ σf·λ dλ.
  if (n == 1) big_lambda = m_fl_excitation[m].total();
  s.cache.fl_lambda_sum[m] = big_lambda;
  if (!m_fluorescent[m] || !(big_lambda > 0.0)) {
    std::fill(fo, fo + n, 0.0f);
    std::fill(fi, fi + n, 0.0f);
    return;
  }
  const double q = mat.fluorescence.quantum_yield;
  for (int i = 0; i < n; ++i) {
    const double l = s.cache.lambda_nm[i];
    fo[i] = static_cast<float>(q * std::max(0.0, m_fl_emission[m].eval(l)) / l * big_lambda);
    fi[i] = static_cast<float>(fi[i] / big_lambda);
  }
}

}  // namespace prizma::render
