#include "prizma/relight/relight_matrix.h"

#include <cmath>

#include "prizma/spectral/colour.h"

namespace prizma::relight {

RelightMatrix::RelightMatrix(const spectral::BinLayout& bins, const std::vector<LightSpec>& lights,
                             const RelightOptions& opts)
    : m_bins(bins.size()), m_options(opts) {
  const spectral::ColorMatching& cmf = spectral::ColorMatching::get(opts.cmf);
  // Per light: exact ∫_{bin} E·cmf dλ (normalised unless absolute), times the light's scale.
  m_per_light.reserve(lights.size());
  for (const LightSpec& light : lights) {
    m_per_light.push_back(spectral::relight_weights(cmf, light, bins, opts.units));
    m_mix_white += m_per_light.back().rowwise().sum();
  }
  // Bradford from the mix's white (at its own luminance) to D65 at the same luminance.
  if (opts.adapt_to_d65 && m_mix_white.y() > 0.0) {
    m_adaptation = spectral::bradford_adaptation(m_mix_white / m_mix_white.y(), spectral::white_d65());
  }
  const double exposure = std::exp2(opts.exposure_ev);
  m_stacked.resize(3, static_cast<Eigen::Index>(m_bins) * static_cast<Eigen::Index>(lights.size()));
  for (std::size_t l = 0; l < m_per_light.size(); ++l) {
    m_per_light[l] = exposure * m_adaptation * m_per_light[l];
    m_stacked.middleCols(static_cast<Eigen::Index>(l) * m_bins, m_bins) = m_per_light[l].cast<float>();
  }
}

}  // namespace prizma::relight
