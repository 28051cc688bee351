// The kernels of a tile: the guides gathered around the tile (borders replicated), then, for each
// neighbour offset, the patch and feature distances and their weights (kernel_simd.cpp), normalised;
// and the per-pixel choice of k by SURE that compute_weights makes once (docs/denoise.md).
#include "prizma/denoise/filter_weights.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

#include <Eigen/Dense>

#include "kernel_simd.h"
#include "prizma/denoise/denoise.h"
#include "prizma/spectral/error.h"

namespace prizma::denoise {

// What compute_weights derives once from the guides: the distances' ε, each feature's τ, and the
// 1/k² each pixel's kernel uses (chosen by SURE; empty when one k serves every pixel).
struct FilterWeights::Derived {
  float eps = 0.0f;
  std::vector<float> feature_tau;  // absolute, per feature
  std::vector<float> inv_k2;       // per pixel, row-major
  std::vector<int> exact;          // indices of the exact features (the regression's)
  std::vector<double> exact_scale; // 1 / each one's range over the image (1 for a constant plane)
};

namespace {

// ε of the distances: negligible against any variance the image holds (1e-10 of the mean squared
// luminance, Rousselle et al. 2012 use 1e-10 for colours in [0, 1]), but never 0, so that two
// noise-free pixels of equal value are at distance 0 and of different values far apart.
float distance_epsilon(const GuidePlane& lum) {
  double sum = 0.0;
  for (float v : lum.value) sum += std::abs(static_cast<double>(v));
  const double mean = lum.value.empty() ? 0.0 : sum / static_cast<double>(lum.value.size());
  return static_cast<float>(1e-10 * mean * mean) + std::numeric_limits<float>::min();
}

void check_options(const DenoiseOptions& o) {
  const std::string input = "denoise options";
  auto range = [&](const char* name, int v, int lo, int hi) {
    if (v < lo || v > hi)
      throw spectral::InputError(input, std::string(name) + " " + std::to_string(v) + " is outside [" +
                                            std::to_string(lo) + ", " + std::to_string(hi) + "]");
  };
  range("window radius", o.window_radius_px, 1, 15);
  range("patch radius", o.patch_radius_px, 0, 7);
  range("tile size", o.tile_size_px, 8, 64);
  auto positive = [&](const char* name, float v, bool zero_allowed) {
    if (!std::isfinite(v) || v < 0.0f || (!zero_allowed && v == 0.0f))
      throw spectral::InputError(input, std::string(name) + " " + std::to_string(v) + " must be " +
                                            (zero_allowed ? "finite and ≥ 0" : "finite and > 0"));
  };
  positive("patch k", o.patch_k, false);
  positive("patch k wide", o.patch_k_wide, true);
  range("SURE radius", o.sure_radius_px, 0, 15);
  positive("centre threshold", o.centre_threshold_se, true);
  positive("feature k", o.feature_k, false);
  positive("feature tau", o.feature_tau, false);
}

// Per-thread buffers of tile_kernels (reused from tile to tile).
struct TileScratch {
  std::vector<float> lum, lum_var, d2, hsum;
  std::vector<float> inv_k2[detail::kMaxCandidates], weights[detail::kMaxCandidates];
  std::vector<float> filtered[detail::kMaxCandidates];  // the SURE selection's filtered luminance
  std::vector<std::vector<float>> feature_value, feature_var, feature_den;
  std::vector<detail::TileFeature> features;
};

// plane(clamp(x), clamp(y)) into a rows × cols grid whose (0, 0) is image pixel (gx0, gy0).
void gather(const std::vector<float>& plane, int width, int height, int gx0, int gy0, int cols, int rows,
            std::vector<float>& out) {
  out.resize(static_cast<std::size_t>(rows) * cols);
  for (int y = 0; y < rows; ++y) {
    const int sy = std::clamp(gy0 + y, 0, height - 1);
    const float* src = plane.data() + static_cast<std::size_t>(sy) * width;
    float* dst = out.data() + static_cast<std::size_t>(y) * cols;
    for (int x = 0; x < cols; ++x) dst[x] = src[std::clamp(gx0 + x, 0, width - 1)];
  }
}

void gather_or_zero(const std::vector<float>& plane, int width, int height, int gx0, int gy0, int cols, int rows,
                    std::vector<float>& out) {
  if (plane.empty())
    out.assign(static_cast<std::size_t>(rows) * cols, 0.0f);
  else
    gather(plane, width, height, gx0, gy0, cols, rows, out);
}

// The 1/k² of one candidate: the same for every pixel, or a per-pixel plane of the image.
struct Candidate {
  float inv_k2 = 1.0f;
  const std::vector<float>* plane = nullptr;
};

// What the tile computation reads: the guides, the options and what compute_weights derived.
struct WeightsContext {
  const DenoiseGuides& guides;
  const DenoiseOptions& options;
  float eps;
  const std::vector<float>& feature_tau;
};

// The features around the tile and their denominators k_f²·max(τ, V_p, |∇f_p|²), the gradient by
// central differences over the replicated border.
void gather_features(const WeightsContext& cx, const PixelRect& rect, int twp, TileScratch& s) {
  const DenoiseGuides& g = cx.guides;
  const int r = cx.options.window_radius_px, th = rect.height;
  const int nf = static_cast<int>(g.features.size()), f_cols = twp + 2 * r, f_rows = th + 2 * r;
  s.feature_value.resize(nf);
  s.feature_var.resize(nf);
  s.feature_den.resize(nf);
  s.features.clear();
  const float kf2 = cx.options.feature_k * cx.options.feature_k;
  for (int k = 0; k < nf; ++k) {
    const GuidePlane& p = g.features[k];
    gather(p.value, g.width, g.height, rect.x0 - r, rect.y0 - r, f_cols, f_rows, s.feature_value[k]);
    gather_or_zero(p.variance, g.width, g.height, rect.x0 - r, rect.y0 - r, f_cols, f_rows, s.feature_var[k]);
    std::vector<float>& den = s.feature_den[k];
    den.assign(static_cast<std::size_t>(th) * twp, 1.0f);
    const float* v = s.feature_value[k].data();
    const float* var = s.feature_var[k].data();
    for (int y = 0; y < th; ++y)
      for (int x = 0; x < rect.width; ++x) {
        const std::size_t c = static_cast<std::size_t>(y + r) * f_cols + x + r;
        const float gx = 0.5f * (v[c + 1] - v[c - 1]), gy = 0.5f * (v[c + f_cols] - v[c - f_cols]);
        den[static_cast<std::size_t>(y) * twp + x] = kf2 * std::max({cx.feature_tau[k], var[c], gx * gx + gy * gy});
      }
    // The exact features are regressed on (regress_tile), not tested.
    if (!p.exact) s.features.push_back({s.feature_value[k].data(), s.feature_var[k].data(), den.data()});
  }
}

// Every candidate's normalised kernels of the tile into s.weights[c]: offset-major planes of
// th rows × twp (padded) floats, zero where the neighbour is outside the image.
void tile_weights(const WeightsContext& cx, const PixelRect& rect, const std::vector<Candidate>& candidates,
                  TileScratch& s) {
  const DenoiseGuides& g = cx.guides;
  const int w = g.width, h = g.height;
  const int r = cx.options.window_radius_px, f = cx.options.patch_radius_px, n = 2 * r + 1;
  const int tw = rect.width, th = rect.height, twp = detail::padded(tw);
  const int region_wp = detail::padded(twp + 2 * f);
  const int lum_cols = region_wp + 2 * r, lum_rows = th + 2 * f + 2 * r;
  // The guides around the tile, borders replicated, so every read of the offset loop is in range.
  gather(g.luminance.value, w, h, rect.x0 - r - f, rect.y0 - r - f, lum_cols, lum_rows, s.lum);
  gather(g.luminance.variance, w, h, rect.x0 - r - f, rect.y0 - r - f, lum_cols, lum_rows, s.lum_var);
  gather_features(cx, rect, twp, s);

  const int plane = th * twp;
  s.d2.resize(static_cast<std::size_t>(th + 2 * f) * region_wp);
  s.hsum.resize(static_cast<std::size_t>(th + 2 * f) * twp);
  detail::OffsetJob job;
  job.candidates = static_cast<int>(candidates.size());
  for (int c = 0; c < job.candidates; ++c) {
    std::vector<float>& k2 = s.inv_k2[c];
    if (candidates[c].plane)
      gather(*candidates[c].plane, w, h, rect.x0, rect.y0, twp, th, k2);
    else
      k2.assign(static_cast<std::size_t>(plane), candidates[c].inv_k2);
    s.weights[c].resize(static_cast<std::size_t>(n) * n * plane);
    job.inv_k2[c] = k2.data();
  }
  job.tile_w = tw;
  job.tile_h = th;
  job.tile_wp = twp;
  job.window_radius = r;
  job.patch_radius = f;
  job.lum = s.lum.data();
  job.lum_var = s.lum_var.data();
  job.lum_stride = lum_cols;
  job.eps = cx.eps;
  job.centre_t2 = cx.options.centre_threshold_se * cx.options.centre_threshold_se;
  job.inv_patch_area = 1.0f / static_cast<float>((2 * f + 1) * (2 * f + 1));
  job.features = s.features.data();
  job.feature_count = static_cast<int>(s.features.size());
  job.feature_stride = twp + 2 * r;
  job.d2 = s.d2.data();
  job.hsum = s.hsum.data();
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx) {
      const std::size_t o = static_cast<std::size_t>((dy + r) * n + dx + r);
      job.dx = dx;
      job.dy = dy;
      for (int c = 0; c < job.candidates; ++c) job.weights[c] = s.weights[c].data() + o * plane;
      detail::offset_weights(job);
      // Neighbours outside the image weigh nothing.
      for (int c = 0; c < job.candidates; ++c)
        for (int y = 0; y < th; ++y) {
          const int qy = rect.y0 + y + dy;
          float* row = job.weights[c] + static_cast<std::size_t>(y) * twp;
          if (qy < 0 || qy >= h) {
            std::fill(row, row + tw, 0.0f);
            continue;
          }
          for (int x = 0; x < tw; ++x)
            if (rect.x0 + x + dx < 0 || rect.x0 + x + dx >= w) row[x] = 0.0f;
        }
    }
  for (int c = 0; c < job.candidates; ++c) detail::normalise_kernels(s.weights[c].data(), n * n, plane);
}

// λ of the regression below, relative to each feature's variance over the kernel: the fitted
// slopes are shrunk by about 1/(1 + λ). On mri_head at 128² and 64 spp, 2 did best of 0.1, 0.5, 2,
// 4 and 8 (docs/denoise.md, "The first-hit guides").
constexpr double kExactRidge = 2.0;

// First-order regression on the exact features (NFOR's, Bitterli et al. 2016, with the kernels
// above as its weights): each pixel's kernel w becomes the row of the weighted least-squares hat
// matrix that evaluates, at the pixel, the plane fitted over its window in the exact features,
// H(q) = w_q · x_qᵀ (Xᵀ W X + Λ)⁻¹ e₁, x_q = (1, s·(f_q − f_p)) (each feature scaled by 1/its
// range over the image), Λ a ridge on the feature terms only. Σ_q H(q) = 1 (the intercept's
// equation) and a pixel whose kernel is its own keeps it.
// The fit reconstructs detail the features see (the skin's normals, the albedo) that the kernels
// alone average away. H depends on the guides only, so it is as light-independent as w.
void regress_tile(const std::vector<int>& exact, const std::vector<double>& exact_scale, int r, const PixelRect& rect,
                  TileScratch& s, int candidate = 0) {
  const int m = static_cast<int>(exact.size());
  if (m == 0) return;
  const int n = 2 * r + 1, twp = detail::padded(rect.width), f_cols = twp + 2 * r;
  const std::size_t plane = static_cast<std::size_t>(rect.height) * twp;
  Eigen::MatrixXd a(m + 1, m + 1);
  // x_q of each neighbour with a weight, gathered once for the fit and for the hat matrix's row.
  std::vector<Eigen::VectorXd> xs(static_cast<std::size_t>(n) * n, Eigen::VectorXd(m + 1));
  for (int y = 0; y < rect.height; ++y)
    for (int px = 0; px < rect.width; ++px) {
      const std::size_t t = static_cast<std::size_t>(y) * twp + px;
      const std::size_t centre = static_cast<std::size_t>(y + r) * f_cols + px + r;
      a.setZero();
      for (int o = 0; o < n * n; ++o) {
        const double w = s.weights[candidate][o * plane + t];
        if (w == 0.0) continue;
        Eigen::VectorXd& x = xs[static_cast<std::size_t>(o)];
        const std::size_t q = centre + static_cast<std::ptrdiff_t>(o / n - r) * f_cols + (o % n - r);
        x[0] = 1.0;
        for (int k = 0; k < m; ++k)
          x[k + 1] = exact_scale[k] * (static_cast<double>(s.feature_value[exact[k]][q]) - s.feature_value[exact[k]][centre]);
        a.selfadjointView<Eigen::Lower>().rankUpdate(x, w);  // the lower triangle, which ldlt() reads
      }
      // Ridge: λ times each feature's weighted variance over the kernel (a(0, 0) = Σw = 1), so
      // the shrinkage is the same whatever the feature's scale or local spread; the small constant
      // keeps a feature that is flat over the kernel out of the fit.
      for (int k = 1; k <= m; ++k) a(k, k) += kExactRidge * std::max(a(k, k) - a(k, 0) * a(k, 0) / a(0, 0), 0.0) + 1e-9;
      const Eigen::VectorXd c = a.ldlt().solve(Eigen::VectorXd::Unit(m + 1, 0));
      for (int o = 0; o < n * n; ++o) {
        float& w = s.weights[candidate][o * plane + t];
        if (w == 0.0f) continue;
        w = static_cast<float>(w * xs[static_cast<std::size_t>(o)].dot(c));
      }
    }
}

// Averages `plane` over the (2s+1)² box around each pixel that lies inside the image, in double and
// in a fixed order (rows, then columns).
std::vector<float> box_mean(const std::vector<float>& plane, int w, int h, int s) {
  std::vector<double> rows(plane.size());
  tbb::parallel_for(0, h, [&](int y) {
    for (int x = 0; x < w; ++x) {
      double t = 0.0;
      for (int u = std::max(0, x - s); u <= std::min(w - 1, x + s); ++u) t += plane[static_cast<std::size_t>(y) * w + u];
      rows[static_cast<std::size_t>(y) * w + x] = t;
    }
  });
  std::vector<float> out(plane.size());
  tbb::parallel_for(0, h, [&](int y) {
    const int y0 = std::max(0, y - s), y1 = std::min(h - 1, y + s);
    for (int x = 0; x < w; ++x) {
      double t = 0.0;
      for (int v = y0; v <= y1; ++v) t += rows[static_cast<std::size_t>(v) * w + x];
      const int cols = std::min(w - 1, x + s) - std::max(0, x - s) + 1;
      out[static_cast<std::size_t>(y) * w + x] = static_cast<float>(t / (cols * (y1 - y0 + 1)));
    }
  });
  return out;
}

// The per-pixel choice between k and k_wide (SURE-based filter selection: Li, Wu, Chuang 2012;
// Rousselle et al. 2013), made on the luminance: for each candidate c, Stein's unbiased estimate of
// the squared error of the filtered luminance, SURE_c(p) = (ŷ_c(p) − y(p))² − V(p) + 2·V(p)·W_c(p, p),
// treating the weights as fixed; averaged over a (2s+1)² box (one pixel's estimate is too noisy to
// choose on); the smaller wins, k on ties. A function of the guides only, so the chosen kernels
// are as light-independent as k.
std::vector<float> choose_inv_k2(const WeightsContext& cx) {
  const DenoiseGuides& g = cx.guides;
  const int w = g.width, h = g.height, tile = cx.options.tile_size_px;
  const int r = cx.options.window_radius_px, n = 2 * r + 1, centre = r * n + r;
  const float inv[2] = {1.0f / (cx.options.patch_k * cx.options.patch_k),
                        1.0f / (cx.options.patch_k_wide * cx.options.patch_k_wide)};
  const std::vector<Candidate> candidates = {{inv[0], nullptr}, {inv[1], nullptr}};
  std::vector<float> sure[2] = {std::vector<float>(g.luminance.value.size()), std::vector<float>(g.luminance.value.size())};
  const int tiles_x = (w + tile - 1) / tile, tiles_y = (h + tile - 1) / tile;
  tbb::parallel_for(0, tiles_x * tiles_y, [&](int index) {
    thread_local TileScratch s;
    const int x0 = index % tiles_x * tile, y0 = index / tiles_x * tile;
    const PixelRect tr{x0, y0, std::min(tile, w - x0), std::min(tile, h - y0)};
    tile_weights(cx, tr, candidates, s);
    // ŷ_c = Σ_o W_c(o)·y(p + o) over the tile, offset by offset on the gathered luminance (the
    // neighbours outside the image have weight 0, their replicated values add nothing).
    const int twp = detail::padded(tr.width), f = cx.options.patch_radius_px;
    const int lum_cols = detail::padded(twp + 2 * f) + 2 * r;
    const std::size_t plane = static_cast<std::size_t>(tr.height) * twp;
    for (int c = 0; c < 2; ++c) {
      std::vector<float>& filtered = s.filtered[c];
      filtered.assign(plane, 0.0f);
      for (int o = 0; o < n * n; ++o) {
        const float* v = s.lum.data() + static_cast<std::size_t>(f + r + o / n - r) * lum_cols + (f + r + o % n - r);
        detail::multiply_add_rows(s.weights[c].data() + o * plane, twp, v, lum_cols, filtered.data(), twp, tr.height,
                                  twp);
      }
    }
    for (int y = 0; y < tr.height; ++y)
      for (int x = 0; x < tr.width; ++x) {
        const std::size_t t = static_cast<std::size_t>(y) * twp + x;
        const std::size_t p = static_cast<std::size_t>(tr.y0 + y) * w + tr.x0 + x;
        const double yp = g.luminance.value[p], vp = g.luminance.variance[p];
        for (int c = 0; c < 2; ++c) {
          const double e = s.filtered[c][t] - yp;
          sure[c][p] = static_cast<float>(e * e - vp + 2.0 * vp * s.weights[c][centre * plane + t]);
        }
      }
  });
  const std::vector<float> a = box_mean(sure[0], w, h, cx.options.sure_radius_px);
  const std::vector<float> b = box_mean(sure[1], w, h, cx.options.sure_radius_px);
  std::vector<float> chosen(a.size());
  for (std::size_t p = 0; p < a.size(); ++p) chosen[p] = b[p] < a[p] ? inv[1] : inv[0];
  return chosen;
}

}  // namespace

void FilterWeights::tile_kernels(const PixelRect& rect, std::vector<float>& out) const {
  if (rect.x0 < 0 || rect.y0 < 0 || rect.width < 1 || rect.height < 1 || rect.x0 + rect.width > m_width ||
      rect.y0 + rect.height > m_height)
    throw std::out_of_range("FilterWeights::tile_kernels: rectangle outside the image");
  thread_local TileScratch s;
  const WeightsContext cx{*m_guides, m_options, m_derived->eps, m_derived->feature_tau};
  Candidate chosen{1.0f / (m_options.patch_k * m_options.patch_k), nullptr};
  if (!m_derived->inv_k2.empty()) chosen.plane = &m_derived->inv_k2;
  tile_weights(cx, rect, {chosen}, s);
  regress_tile(m_derived->exact, m_derived->exact_scale, m_options.window_radius_px, rect, s);
  // Offset-major, rows unpadded.
  const int k = kernel_size(), twp = detail::padded(rect.width);
  const std::size_t plane = static_cast<std::size_t>(rect.height) * twp, count = static_cast<std::size_t>(rect.pixel_count());
  out.resize(static_cast<std::size_t>(k) * count);
  for (int o = 0; o < k; ++o)
    for (int y = 0; y < rect.height; ++y)
      std::copy_n(s.weights[0].data() + o * plane + static_cast<std::size_t>(y) * twp, rect.width,
                  out.data() + o * count + static_cast<std::size_t>(y) * rect.width);
}

std::vector<std::string> FilterWeights::guide_names() const {
  std::vector<std::string> names{m_guides->luminance.name.empty() ? std::string("luminance") : m_guides->luminance.name};
  for (const GuidePlane& f : m_guides->features) names.push_back(f.name);
  return names;
}

std::vector<float> FilterWeights::kernel(int x, int y) const {
  if (x < 0 || y < 0 || x >= m_width || y >= m_height)
    throw std::out_of_range("FilterWeights::kernel: pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                            ") outside the image");
  std::vector<float> out;
  tile_kernels({x, y, 1, 1}, out);
  return out;
}

FilterWeights compute_weights(const DenoiseGuides& guides, const DenoiseOptions& options) {
  return compute_weights(DenoiseGuides(guides), options);
}

namespace {

// Each feature plane filtered by non-local means on itself (its own values and variances as the
// guide), as NFOR filters its features before regressing on them (Bitterli et al. 2016): the
// renderer's guides (depth, scatter fraction) are Monte Carlo means as noisy as the luminance, and
// the feature test, made for nearly noise-free features, would cut neighbours that only differ by
// that noise. A feature's own kernels keep its edges (two sides far apart beyond their noise), the
// luminance's would blur the edges only the feature sees. The values become Σ W·f and the variances
// Σ W²·V (the filtered estimate's variance with W held fixed). A plane without variance is noise-free
// and kept. The kernels depend on the feature alone, so the weights stay independent of every light.
void prefilter_features(DenoiseGuides& guides, const DenoiseOptions& options) {
  for (GuidePlane& f : guides.features) {
    if (f.variance.empty() || f.exact) continue;
    DenoiseGuides own{guides.width, guides.height, f, {}};
    const FilterWeights w = compute_weights(std::move(own), options);
    f.value = apply(w, f.value, 1, KernelPower::Weights);
    f.variance = apply(w, f.variance, 1, KernelPower::SquaredWeights);
  }
}

}  // namespace

FilterWeights compute_weights(DenoiseGuides&& guides, const DenoiseOptions& options) {
  check_guides(guides);
  check_options(options);
  prefilter_features(guides, options);
  auto derived = std::make_shared<FilterWeights::Derived>();
  derived->eps = distance_epsilon(guides.luminance);
  for (std::size_t k = 0; k < guides.features.size(); ++k) {
    const GuidePlane& p = guides.features[k];
    const auto [lo, hi] = std::minmax_element(p.value.begin(), p.value.end());
    const double range = static_cast<double>(*hi) - *lo;
    derived->feature_tau.push_back(
        static_cast<float>(options.feature_tau * range * range) + std::numeric_limits<float>::min());
    if (p.exact) {  // regressed on, scaled by 1 / its range (1 for a constant plane)
      derived->exact.push_back(static_cast<int>(k));
      derived->exact_scale.push_back(range > 0.0 ? 1.0 / range : 1.0);
    }
  }
  if (options.patch_k_wide > 0.0f && options.patch_k_wide != options.patch_k)
    derived->inv_k2 = choose_inv_k2({guides, options, derived->eps, derived->feature_tau});
  FilterWeights w;
  w.m_width = guides.width;
  w.m_height = guides.height;
  w.m_options = options;
  w.m_guides = std::make_shared<const DenoiseGuides>(std::move(guides));
  w.m_derived = std::move(derived);
  return w;
}

}  // namespace prizma::denoise
