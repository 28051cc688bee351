#pragma once
// CIE colour matching functions and the exact per-bin relight weights.
#include <Eigen/Core>
#include <string>
#include <string_view>
#include <vector>

#include "prizma/spectral/bin_layout.h"
#include "prizma/spectral/spectrum.h"

namespace prizma::spectral {

enum class Observer { Cie1931_2deg, Cie1964_10deg, Cie2012_2deg, Cie2012_10deg };

// Accepts "1931" / "cie1931" / "2deg", "1964" / "10deg", "2012" / "2006" / "2012-2", "2012-10".
Observer parse_observer(std::string_view name, std::string_view input = "cmf");
std::string observer_name(Observer obs);  // "cie1931-2", "cie1964-10", "cie2012-2", "cie2012-10"

class ColorMatching {
 public:
  // Loads (once, thread-safe) the 1 nm table from data/.
  static const ColorMatching& get(Observer obs);
  const Spectrum& x() const { return m_xyz[0]; }
  const Spectrum& y() const { return m_xyz[1]; }
  const Spectrum& z() const { return m_xyz[2]; }
  const Spectrum& channel(int c) const { return m_xyz[c]; }
  double lo_nm() const;
  double hi_nm() const;
  Observer observer() const { return m_observer; }
  // XYZ of a spectrum (∫ s·cmf dλ over the table, no normalisation).
  Eigen::Vector3d integrate(const Spectrum& s) const;

 private:
  ColorMatching(Observer obs, Spectrum x, Spectrum y, Spectrum z);
  Observer m_observer;
  Spectrum m_xyz[3];
};

enum class LightUnits {
  // Scale 1 means a perfect white (T = 1 in every bin) under the light has Y = 1.
  RelativeToWhite,
  // Weights are ∫ E·cmf dλ in the light's own units (no normalisation).
  Absolute,
};

// The 3×n relight matrix M[c][i] = k·∫_{bin i} E(λ)·cmf_c(λ) dλ, integrated exactly from the
// tables (never a product of bin averages). With RelativeToWhite, k = 1/∫_{bins} E·ȳ dλ so that
// Σ_i M[1][i] = 1. The colour matching functions are zero outside their table (the CIE 2012 tables
// start at 390 nm; below it their contribution is under 1e-4 of Y), so any bins are accepted.
// Throws InputError (input "light") when the light has no energy where ȳ > 0 inside the bins.
Eigen::Matrix<double, 3, Eigen::Dynamic> relight_weights(const ColorMatching& cmf, const Spectrum& light,
                                                          const BinLayout& bins,
                                                          LightUnits units = LightUnits::RelativeToWhite);

// A one-line note when `bins` reach outside the table of `cmf` (those parts weigh nothing), else "".
std::string cmf_coverage_note(const ColorMatching& cmf, const BinLayout& bins);

}  // namespace prizma::spectral
