#include "prizma/spectral/relight_matrix.h"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "prizma/spectral/colour.h"
#include "prizma/spectral/error.h"

namespace prizma::spectral {

void RelightOptions::validate(const std::string& exposure_input) const {
  if (!std::isfinite(exposure_ev) || std::abs(exposure_ev) > kMaxExposureEv)
    throw InputError(exposure_input, "must be a finite number of stops within ±64");
}

RelightMatrix::RelightMatrix(const BinLayout& bins, const std::vector<LightSpectrum>& lights,
                             const RelightOptions& opts)
    : m_bins(bins.size()), m_options(opts) {
  const ColorMatching& cmf = ColorMatching::get(opts.cmf);
  // Per light: exact ∫_{bin} E·cmf dλ (normalised unless absolute), times the light's scale.
  m_per_light.reserve(lights.size());
  for (const LightSpectrum& light : lights) {
    m_per_light.push_back(relight_weights(cmf, light, bins, opts.units));
    m_mix_white += m_per_light.back().rowwise().sum();
  }
  // Bradford from the mix's white (at its own luminance) to D65 at the same luminance.
  if (opts.adapt_to_d65 && m_mix_white.y() > 0.0) {
    m_adaptation = bradford_adaptation(m_mix_white / m_mix_white.y(), white_d65());
  }
  const double exposure = std::exp2(opts.exposure_ev);
  m_output = exposure * m_adaptation;
  // Bin averages of each light for bispectral terms, normalised as relight_weights normalises.
  for (const LightSpectrum& light : lights) {
    Eigen::VectorXd e = Eigen::VectorXd::Zero(m_bins);
    if (!light.off && light.scale != 0.0) {
      double norm = 1.0;
      if (opts.units == LightUnits::RelativeToWhite)
        norm = 1.0 / relight_weights(cmf, light.spectrum, bins, LightUnits::Absolute).row(1).sum();
      for (int i = 0; i < m_bins; ++i)
        e[i] = light.scale * norm * light.spectrum.integrate(bins.lo_nm(i), bins.hi_nm(i)) / bins.width_nm(i);
    }
    m_bin_average.push_back(e);
  }
  m_stacked.resize(3, static_cast<Eigen::Index>(m_bins) * static_cast<Eigen::Index>(lights.size()));
  for (std::size_t l = 0; l < m_per_light.size(); ++l) {
    m_per_light[l] = exposure * m_adaptation * m_per_light[l];
    m_stacked.middleCols(static_cast<Eigen::Index>(l) * m_bins, m_bins) = m_per_light[l].cast<float>();
    // Weights a float cannot hold relight as ±inf and NaN: a black image. A relative light's scale is
    // bounded (kMaxLightScale), so this is an absolute light whose table is in very large units.
    if (!m_stacked.middleCols(static_cast<Eigen::Index>(l) * m_bins, m_bins).allFinite()) {
      std::ostringstream largest;
      largest << std::setprecision(3) << m_per_light[l].cwiseAbs().maxCoeff();
      throw InputError("light", "\"" + lights[l].text + "\": its relight weights (up to " + largest.str() +
                                              ") overflow a float; give a smaller scale or exposure");
    }
  }
}

Matrix3Xd bin_cmf_integrals(Observer observer, const BinLayout& bins) {
  const ColorMatching& cmf = ColorMatching::get(observer);
  Matrix3Xd m(3, bins.size());
  for (int i = 0; i < bins.size(); ++i)
    for (int c = 0; c < 3; ++c) m(c, i) = cmf.channel(c).integrate(bins.lo_nm(i), bins.hi_nm(i));
  return m;
}

}  // namespace prizma::spectral
