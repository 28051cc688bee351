#pragma once
// RelightMatrix: per light layer the 3×n matrix taking the layer's transport bins to CIE XYZ, with
// exposure and optional chromatic adaptation folded in, and all layers stacked side by side.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "prizma/spectral/light_spectrum.h"
#include "prizma/spectral/bin_layout.h"
#include "prizma/spectral/colour_matching.h"

namespace prizma::spectral {

// The exposure every tool accepts, in stops either way: 2^64 ≈ 1.8e19, which the float weights hold
// for any light up to kMaxLightScale (light_spectrum.h).
constexpr double kMaxExposureEv = 64.0;

struct RelightOptions {
  Observer cmf = Observer::Cie1931_2deg;
  // RelativeToWhite: a perfect white (T = 1) under each light at scale 1 has Y = 1.
  LightUnits units = LightUnits::RelativeToWhite;
  double exposure_ev = 0.0;  // output multiplied by 2^exposure_ev; finite, within ±kMaxExposureEv
  // Bradford adaptation from the white of the light mix (XYZ of T = 1 under all lights) to D65,
  // preserving the white's luminance. Ignored when every light is off.
  bool adapt_to_d65 = false;

  // Throws InputError(exposure_input, "must be a finite number of stops within ±64") for an exposure
  // out of range; `exposure_input` names it as the user gave it ("--exposure", "state: exposure").
  void validate(const std::string& exposure_input = "exposure") const;
};

using Matrix3Xd = Eigen::Matrix<double, 3, Eigen::Dynamic>;
using Matrix3Xf = Eigen::Matrix<float, 3, Eigen::Dynamic>;

class RelightMatrix {
 public:
  RelightMatrix() = default;
  // One LightSpectrum per transport layer, in the image's layer order. The weights are exact integrals
  // of light × CMF over each bin (relight_weights); "off" layers get a zero matrix.
  // Throws InputError (from relight_weights) when a light has no energy in the bins.
  RelightMatrix(const BinLayout& bins, const std::vector<LightSpectrum>& lights,
                const RelightOptions& opts);

  int light_count() const { return static_cast<int>(m_per_light.size()); }
  int bin_count() const { return m_bins; }
  // Final 3×n matrix of light l (exposure and adaptation included).
  const Matrix3Xd& light(int l) const { return m_per_light[static_cast<std::size_t>(l)]; }
  // All lights side by side, 3×(L·n), float: columns [l·n, (l+1)·n) belong to light l.
  const Matrix3Xf& stacked() const { return m_stacked; }
  // XYZ of a perfect white (T = 1 in every bin of every layer) under the mix, before exposure and
  // adaptation.
  const Eigen::Vector3d& mix_white_xyz() const { return m_mix_white; }
  // The adaptation applied (identity unless adapt_to_d65 and some light is on).
  const Eigen::Matrix3d& adaptation() const { return m_adaptation; }
  const RelightOptions& options() const { return m_options; }
  // Bispectral (fluorescent) images, docs/fluorescence.md: light l's bin averages ē_i =
  // (1/Δλ_i)·∫_{bin i} E dλ with the same normalisation and scale as light(l) (zero when off), and
  // the 3×3 applied after the per-pixel product (exposure × adaptation), so that the re-radiated
  // XYZ is output() · Σ_in K[c][in]·ē[in], K from the CMFs integrated over the out bins
  // (bin_cmf_integrals()).
  const Eigen::VectorXd& light_bin_average(int l) const { return m_bin_average[static_cast<std::size_t>(l)]; }
  const Eigen::Matrix3d& output() const { return m_output; }

 private:
  int m_bins = 0;
  std::vector<Matrix3Xd> m_per_light;
  Matrix3Xf m_stacked;
  Eigen::Vector3d m_mix_white = Eigen::Vector3d::Zero();
  Eigen::Matrix3d m_adaptation = Eigen::Matrix3d::Identity();
  std::vector<Eigen::VectorXd> m_bin_average;
  Eigen::Matrix3d m_output = Eigen::Matrix3d::Identity();
  RelightOptions m_options;
};

// ∫_{bin} cmf_c dλ for every bin (3×n): the XYZ of a radiance constant inside each bin.
Matrix3Xd bin_cmf_integrals(Observer observer, const BinLayout& bins);

}  // namespace prizma::spectral
