#include "prizma/render/film.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace prizma::render {
namespace {

// The error target looks at a pixel only after this many samples.
constexpr std::int64_t kMinAdaptiveSamples = 16;

}  // namespace

Film::Film(Layout spec) : m_layout(std::move(spec)) {
  const std::size_t pixels = static_cast<std::size_t>(m_layout.width) * m_layout.height;
  m_per_pixel = static_cast<std::size_t>(m_layout.lights) * m_layout.bins.size();
  m_per_pixel_fl = static_cast<std::size_t>(m_layout.lights) * m_layout.bispectral.size();
  const bool adaptive = m_layout.target_error > 0.0;
  m_live.sum.assign(pixels * m_per_pixel, 0.0);
  m_live.sum_sq.assign(m_layout.variance ? pixels * m_per_pixel : 0, 0.0);
  m_live.total_sum.assign(adaptive ? pixels : 0, 0.0);
  m_live.total_sq.assign(adaptive ? pixels : 0, 0.0);
  m_live.sum_fl.assign(pixels * m_per_pixel_fl, 0.0);
  m_live.sum_g.assign(pixels * m_layout.guides.size(), 0.0);
  m_live.sum_g_sq.assign(pixels * m_layout.guides.size(), 0.0);
  m_live.count.assign(pixels, 0);
  m_live.converged.assign(pixels, 0);
}

bool Film::add_sample(std::size_t pix, const double* v, const double* vf, const double* g) {
  Sums& s = m_live;
  const std::size_t ng = m_layout.guides.size();
  for (std::size_t k = 0; k < ng; ++k) {
    s.sum_g[pix * ng + k] += g[k];
    s.sum_g_sq[pix * ng + k] += g[k] * g[k];
  }
  if (m_per_pixel_fl > 0) {
    double* acc_fl = s.sum_fl.data() + pix * m_per_pixel_fl;
    for (std::size_t k = 0; k < m_per_pixel_fl; ++k) acc_fl[k] += vf[k];
  }
  double* acc = s.sum.data() + pix * m_per_pixel;
  double sample_total = 0.0;
  for (std::size_t k = 0; k < m_per_pixel; ++k) {
    acc[k] += v[k];
    sample_total += v[k];
  }
  if (m_layout.variance) {
    double* acc_sq = s.sum_sq.data() + pix * m_per_pixel;
    for (std::size_t k = 0; k < m_per_pixel; ++k) acc_sq[k] += v[k] * v[k];
  }
  const std::int64_t nsamp = ++s.count[pix];
  if (!(m_layout.target_error > 0.0)) return false;
  // Relative standard error of the pixel's sum over lights and bins.
  s.total_sum[pix] += sample_total;
  s.total_sq[pix] += sample_total * sample_total;
  if (nsamp < kMinAdaptiveSamples) return false;
  const double n = static_cast<double>(nsamp);
  const double mean = s.total_sum[pix] / n;
  const double var = std::max(0.0, (s.total_sq[pix] / n - mean * mean) * n / (n - 1.0));
  if (!(std::sqrt(var / n) <= m_layout.target_error * std::abs(mean))) return false;
  s.converged[pix] = 1;
  return true;
}

void Film::save() { m_saved = m_live; }

void Film::restore() { std::swap(m_live, m_saved); }

spectral::SpectralImage Film::image(const std::vector<std::string>& names) const {
  const Sums& s = m_live;
  const int nb = m_layout.bins.size();
  const int nl = m_layout.lights;
  const std::size_t pixels = this->pixels();
  spectral::SpectralImage img;
  img.width = m_layout.width;
  img.height = m_layout.height;
  img.bins = m_layout.bins;
  img.lights.resize(nl);
  for (int l = 0; l < nl; ++l) {
    auto& layer = img.lights[l];
    layer.name = names[l];
    layer.data.assign(pixels * nb, 0.0f);
    if (m_layout.variance) layer.variance.assign(pixels * nb, 0.0f);
  }
  for (std::size_t pix = 0; pix < pixels; ++pix) {
    const double n = static_cast<double>(s.count[pix]);
    for (int l = 0; l < nl; ++l) {
      auto& layer = img.lights[l];
      for (int i = 0; i < nb; ++i) {
        const std::size_t k = pix * m_per_pixel + static_cast<std::size_t>(l) * nb + i;
        const double mean = n > 0 ? s.sum[k] / n : 0.0;
        layer.data[pix * nb + i] = static_cast<float>(mean);
        if (m_layout.variance && n > 1) {
          const double var = std::max(0.0, (s.sum_sq[k] / n - mean * mean) * n / (n - 1.0));
          layer.variance[pix * nb + i] = static_cast<float>(var / n);
        }
      }
    }
  }
  const std::size_t ng = m_layout.guides.size();
  for (std::size_t k = 0; k < ng; ++k) {
    spectral::GuideLayer& guide = img.guides.emplace_back();
    guide.name = m_layout.guides[k];
    guide.value.assign(pixels, 0.0f);
    guide.variance.assign(pixels, 0.0f);
    for (std::size_t pix = 0; pix < pixels; ++pix) {
      const double n = static_cast<double>(s.count[pix]);
      const double mean = n > 0 ? s.sum_g[pix * ng + k] / n : 0.0;
      guide.value[pix] = static_cast<float>(mean);
      if (n > 1)
        guide.variance[pix] =
            static_cast<float>(std::max(0.0, (s.sum_g_sq[pix * ng + k] / n - mean * mean) * n / (n - 1.0)) / n);
    }
  }
  if (m_per_pixel_fl > 0) {
    // The bispectral terms (docs/spectral-exr.md, "Bispectral channels"): per light, pairs contiguous.
    const std::size_t np = m_layout.bispectral.size();
    img.reradiation = m_layout.bispectral;
    for (int l = 0; l < nl; ++l) {
      auto& r = img.lights[l].reradiation;
      r.assign(pixels * np, 0.0f);
      for (std::size_t pix = 0; pix < pixels; ++pix) {
        const double n = static_cast<double>(s.count[pix]);
        for (std::size_t k = 0; k < np; ++k)
          r[pix * np + k] =
              n > 0 ? static_cast<float>(s.sum_fl[pix * m_per_pixel_fl + static_cast<std::size_t>(l) * np + k] / n) : 0.0f;
      }
    }
  }
  return img;
}

}  // namespace prizma::render
