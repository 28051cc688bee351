#pragma once
// Spectrum: a tabulated piecewise-linear function of wavelength (nm), zero outside its table
// (except constant spectra, which hold everywhere). Small immutable value type.
#include <vector>

#include "prizma/spectral/bin_layout.h"

namespace prizma::spectral {

class Spectrum {
 public:
  // The zero spectrum.
  Spectrum() = default;
  // A constant spectrum, value v at every wavelength.
  static Spectrum constant(double v);
  // Tabulated: wavelengths strictly increasing, all values finite. Throws InputError (input
  // `input`) otherwise. A single sample is not allowed (use constant()).
  Spectrum(std::vector<double> lambda_nm, std::vector<double> values, std::string_view input = "spectrum");

  bool is_constant() const { return m_constant; }
  const std::vector<double>& wavelengths_nm() const { return m_lambda; }
  const std::vector<double>& values() const { return m_values; }

  // Value at lambda_nm (linear interpolation; 0 outside the table unless constant).
  double eval(double lambda_nm) const;
  // Exact ∫_{lo}^{hi} s(λ) dλ.
  double integrate(double lo_nm, double hi_nm) const;
  // Exact ∫_{lo}^{hi} s(λ)·other(λ) dλ (product of two piecewise-linear functions is piecewise
  // quadratic; integrated exactly on the merged breakpoints).
  double integrate_product(const Spectrum& other, double lo_nm, double hi_nm) const;
  // Bin averages (1/Δλ_i)∫_{bin i} s dλ: the L2 (least-squares) projection onto the
  // piecewise-constant basis of the bins, which is what the seed method's least-squares fit solves.
  std::vector<double> bin_averages(const BinLayout& bins) const;
  // Samples at the given wavelengths (a new tabulated spectrum).
  Spectrum resampled(const std::vector<double>& lambda_nm) const;
  Spectrum scaled(double factor) const;
  double min_value() const;
  double max_value() const;
  // The range where the table is defined ([-inf, inf] for constants).
  double domain_lo_nm() const;
  double domain_hi_nm() const;

 private:
  std::vector<double> m_lambda;
  std::vector<double> m_values;
  bool m_constant = false;
  double m_constant_value = 0.0;
};

}  // namespace prizma::spectral
