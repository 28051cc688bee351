// The kernels of a tile: the guides gathered around the tile (borders replicated), then, for each
// neighbour offset, the patch and feature distances and their weights (kernel_simd.cpp), normalised.
#include "prizma/denoise/filter_weights.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>

#include "kernel_simd.h"
#include "prizma/spectral/error.h"

namespace prizma::denoise {

// What compute_weights derives once from the guides: the distances' ε and each feature's τ.
struct FilterWeights::Derived {
  float eps = 0.0f;
  std::vector<float> feature_tau;  // absolute, per feature
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
  positive("centre threshold", o.centre_threshold_se, true);
  positive("feature k", o.feature_k, false);
  positive("feature tau", o.feature_tau, false);
}

// Per-thread buffers of tile_kernels (reused from tile to tile).
struct TileScratch {
  std::vector<float> lum, lum_var, d2, hsum, weights;
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

}  // namespace

void FilterWeights::tile_kernels(const PixelRect& rect, std::vector<float>& out) const {
  if (rect.x0 < 0 || rect.y0 < 0 || rect.width < 1 || rect.height < 1 || rect.x0 + rect.width > m_width ||
      rect.y0 + rect.height > m_height)
    throw std::out_of_range("FilterWeights::tile_kernels: rectangle outside the image");
  thread_local TileScratch s;
  const DenoiseGuides& g = *m_guides;
  const int r = m_options.window_radius_px, f = m_options.patch_radius_px, n = 2 * r + 1;
  const int tw = rect.width, th = rect.height, twp = detail::padded(tw);
  const int region_wp = detail::padded(twp + 2 * f);
  const int lum_cols = region_wp + 2 * r, lum_rows = th + 2 * f + 2 * r;

  // The guides around the tile, borders replicated, so every read of the offset loop is in range.
  gather(g.luminance.value, m_width, m_height, rect.x0 - r - f, rect.y0 - r - f, lum_cols, lum_rows, s.lum);
  gather(g.luminance.variance, m_width, m_height, rect.x0 - r - f, rect.y0 - r - f, lum_cols, lum_rows, s.lum_var);
  const int nf = static_cast<int>(g.features.size());
  const int f_cols = twp + 2 * r, f_rows = th + 2 * r;
  s.feature_value.resize(nf);
  s.feature_var.resize(nf);
  s.feature_den.resize(nf);
  s.features.resize(nf);
  const float kf2 = m_options.feature_k * m_options.feature_k;
  for (int k = 0; k < nf; ++k) {
    const GuidePlane& p = g.features[k];
    gather(p.value, m_width, m_height, rect.x0 - r, rect.y0 - r, f_cols, f_rows, s.feature_value[k]);
    gather_or_zero(p.variance, m_width, m_height, rect.x0 - r, rect.y0 - r, f_cols, f_rows, s.feature_var[k]);
    // k_f²·max(τ, V_p, |∇f_p|²), the gradient by central differences over the replicated border.
    std::vector<float>& den = s.feature_den[k];
    den.assign(static_cast<std::size_t>(th) * twp, 1.0f);
    const float* v = s.feature_value[k].data();
    const float* var = s.feature_var[k].data();
    for (int y = 0; y < th; ++y)
      for (int x = 0; x < tw; ++x) {
        const std::size_t c = static_cast<std::size_t>(y + r) * f_cols + x + r;
        const float gx = 0.5f * (v[c + 1] - v[c - 1]), gy = 0.5f * (v[c + f_cols] - v[c - f_cols]);
        den[static_cast<std::size_t>(y) * twp + x] =
            kf2 * std::max({m_derived->feature_tau[k], var[c], gx * gx + gy * gy});
      }
    s.features[k] = {s.feature_value[k].data(), s.feature_var[k].data(), den.data()};
  }

  // One offset at a time: unnormalised weights, zero where the neighbour is outside the image.
  const int plane = th * twp;
  s.d2.resize(static_cast<std::size_t>(th + 2 * f) * region_wp);
  s.hsum.resize(static_cast<std::size_t>(th + 2 * f) * twp);
  s.weights.resize(static_cast<std::size_t>(n) * n * plane);
  detail::OffsetJob job;
  job.tile_w = tw;
  job.tile_h = th;
  job.tile_wp = twp;
  job.window_radius = r;
  job.patch_radius = f;
  job.lum = s.lum.data();
  job.lum_var = s.lum_var.data();
  job.lum_stride = lum_cols;
  job.eps = m_derived->eps;
  job.patch_k2 = m_options.patch_k * m_options.patch_k;
  job.centre_t2 = m_options.centre_threshold_se * m_options.centre_threshold_se;
  job.inv_patch_area = 1.0f / static_cast<float>((2 * f + 1) * (2 * f + 1));
  job.features = s.features.data();
  job.feature_count = nf;
  job.feature_stride = f_cols;
  job.d2 = s.d2.data();
  job.hsum = s.hsum.data();
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx) {
      const int o = (dy + r) * n + dx + r;
      float* w = s.weights.data() + static_cast<std::size_t>(o) * plane;
      job.dx = dx;
      job.dy = dy;
      job.weights = w;
      detail::offset_weights(job);
      for (int y = 0; y < th; ++y) {
        const int qy = rect.y0 + y + dy;
        float* row = w + static_cast<std::size_t>(y) * twp;
        if (qy < 0 || qy >= m_height) {
          std::fill(row, row + tw, 0.0f);
          continue;
        }
        for (int x = 0; x < tw; ++x)
          if (rect.x0 + x + dx < 0 || rect.x0 + x + dx >= m_width) row[x] = 0.0f;
      }
    }
  detail::normalise_kernels(s.weights.data(), n * n, plane);

  // Offset-major, rows unpadded.
  out.resize(static_cast<std::size_t>(n) * n * rect.pixel_count());
  for (int o = 0; o < n * n; ++o)
    for (int y = 0; y < th; ++y)
      std::copy_n(s.weights.data() + static_cast<std::size_t>(o) * plane + static_cast<std::size_t>(y) * twp, tw,
                  out.data() + static_cast<std::size_t>(o) * rect.pixel_count() + static_cast<std::size_t>(y) * tw);
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
  check_guides(guides);
  check_options(options);
  auto derived = std::make_shared<FilterWeights::Derived>();
  derived->eps = distance_epsilon(guides.luminance);
  for (const GuidePlane& p : guides.features) {
    const auto [lo, hi] = std::minmax_element(p.value.begin(), p.value.end());
    const double range = static_cast<double>(*hi) - *lo;
    derived->feature_tau.push_back(
        static_cast<float>(options.feature_tau * range * range) + std::numeric_limits<float>::min());
  }
  FilterWeights w;
  w.m_width = guides.width;
  w.m_height = guides.height;
  w.m_options = options;
  w.m_guides = std::make_shared<const DenoiseGuides>(guides);
  w.m_derived = std::move(derived);
  return w;
}

}  // namespace prizma::denoise
