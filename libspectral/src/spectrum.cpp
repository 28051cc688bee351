#include "prizma/spectral/spectrum.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "prizma/spectral/error.h"
#include "text_util.h"

namespace prizma::spectral {

using detail::format_double;

namespace {

// Values at a and b of the linear piece of `s` that covers the open interval (a, b); the caller
// guarantees that no breakpoint of `s` lies strictly inside (a, b). Zero where the interval lies
// outside the table (so the jump to zero at the table's ends is honoured).
void linear_piece(const Spectrum& s, double a, double b, double& fa, double& fb) {
  if (s.is_constant()) {
    fa = fb = s.eval(0.0);
    return;
  }
  const auto& lam = s.wavelengths_nm();
  const auto& val = s.values();
  if (lam.size() < 2 || b <= lam.front() || a >= lam.back()) {
    fa = fb = 0.0;
    return;
  }
  const double mid = 0.5 * (a + b);
  auto it = std::upper_bound(lam.begin(), lam.end(), mid);
  std::size_t j = static_cast<std::size_t>(it - lam.begin());
  j = std::clamp<std::size_t>(j, 1, lam.size() - 1) - 1;  // segment [lam[j], lam[j+1]]
  const double l0 = lam[j], l1 = lam[j + 1];
  const double slope = (val[j + 1] - val[j]) / (l1 - l0);
  fa = val[j] + slope * (a - l0);
  fb = val[j] + slope * (b - l0);
}

// Breakpoints of `s` strictly inside (lo, hi), appended to `out`.
void inner_breakpoints(const Spectrum& s, double lo, double hi, std::vector<double>& out) {
  const auto& lam = s.wavelengths_nm();
  auto it = std::upper_bound(lam.begin(), lam.end(), lo);
  for (; it != lam.end() && *it < hi; ++it) out.push_back(*it);
}

void check_bounds(double lo_nm, double hi_nm) {
  if (std::isnan(lo_nm) || std::isnan(hi_nm)) {
    throw InputError("spectrum", "integration bound is not a number");
  }
}

}  // namespace

Spectrum Spectrum::constant(double v) {
  if (!std::isfinite(v)) throw InputError("spectrum", "constant value is not a finite number: " + format_double(v));
  Spectrum s;
  s.m_constant = true;
  s.m_constant_value = v;
  return s;
}

Spectrum::Spectrum(std::vector<double> lambda_nm, std::vector<double> values, std::string_view input)
    : m_lambda(std::move(lambda_nm)), m_values(std::move(values)) {
  const std::string in(input);
  if (m_lambda.size() != m_values.size()) {
    throw InputError(in, "got " + std::to_string(m_lambda.size()) + " wavelengths but " +
                             std::to_string(m_values.size()) + " values");
  }
  if (m_lambda.size() < 2) {
    throw InputError(in, "a tabulated spectrum needs at least 2 samples, got " + std::to_string(m_lambda.size()));
  }
  for (std::size_t i = 0; i < m_lambda.size(); ++i) {
    if (!std::isfinite(m_lambda[i])) {
      throw InputError(in, "wavelength is not a finite number: " + format_double(m_lambda[i]));
    }
    if (!std::isfinite(m_values[i])) {
      throw InputError(in, "value at " + format_double(m_lambda[i]) + " nm is not a finite number: " +
                               format_double(m_values[i]));
    }
    if (i > 0 && !(m_lambda[i] > m_lambda[i - 1])) {
      throw InputError(in, "wavelengths must be strictly increasing: " + format_double(m_lambda[i]) +
                               " nm follows " + format_double(m_lambda[i - 1]) + " nm");
    }
  }
}

double Spectrum::eval(double lambda_nm) const {
  if (m_constant) return m_constant_value;
  if (m_lambda.size() < 2 || !(lambda_nm >= m_lambda.front() && lambda_nm <= m_lambda.back())) return 0.0;
  auto it = std::upper_bound(m_lambda.begin(), m_lambda.end(), lambda_nm);
  std::size_t j = static_cast<std::size_t>(it - m_lambda.begin());
  if (j >= m_lambda.size()) return m_values.back();
  j -= 1;
  const double t = (lambda_nm - m_lambda[j]) / (m_lambda[j + 1] - m_lambda[j]);
  return m_values[j] + t * (m_values[j + 1] - m_values[j]);
}

double Spectrum::integrate(double lo_nm, double hi_nm) const {
  check_bounds(lo_nm, hi_nm);
  if (hi_nm < lo_nm) return -integrate(hi_nm, lo_nm);
  if (hi_nm == lo_nm) return 0.0;
  if (m_constant) return m_constant_value == 0.0 ? 0.0 : m_constant_value * (hi_nm - lo_nm);
  if (m_lambda.size() < 2) return 0.0;
  // Trapezoids are exact for a piecewise-linear function.
  const double a0 = std::max(lo_nm, m_lambda.front());
  const double b0 = std::min(hi_nm, m_lambda.back());
  if (!(a0 < b0)) return 0.0;
  std::vector<double> pts{a0};
  inner_breakpoints(*this, a0, b0, pts);
  pts.push_back(b0);
  double sum = 0.0;
  for (std::size_t k = 0; k + 1 < pts.size(); ++k) {
    double fa = 0.0, fb = 0.0;
    linear_piece(*this, pts[k], pts[k + 1], fa, fb);
    sum += 0.5 * (fa + fb) * (pts[k + 1] - pts[k]);
  }
  return sum;
}

double Spectrum::integrate_product(const Spectrum& other, double lo_nm, double hi_nm) const {
  check_bounds(lo_nm, hi_nm);
  if (hi_nm < lo_nm) return -integrate_product(other, hi_nm, lo_nm);
  if (hi_nm == lo_nm) return 0.0;
  if (m_constant) return m_constant_value == 0.0 ? 0.0 : m_constant_value * other.integrate(lo_nm, hi_nm);
  if (other.m_constant) return other.m_constant_value == 0.0 ? 0.0 : other.m_constant_value * integrate(lo_nm, hi_nm);
  if (m_lambda.size() < 2 || other.m_lambda.size() < 2) return 0.0;
  // The product is zero outside the intersection of the two tables.
  const double a0 = std::max({lo_nm, m_lambda.front(), other.m_lambda.front()});
  const double b0 = std::min({hi_nm, m_lambda.back(), other.m_lambda.back()});
  if (!(a0 < b0)) return 0.0;
  // Merged breakpoints: on each piece both factors are linear, the product quadratic, and
  // Simpson's rule ((b−a)/6)(2 fa ga + fa gb + fb ga + 2 fb gb) is exact for it.
  std::vector<double> p1, p2;
  inner_breakpoints(*this, a0, b0, p1);
  inner_breakpoints(other, a0, b0, p2);
  std::vector<double> pts;
  pts.reserve(p1.size() + p2.size() + 2);
  pts.push_back(a0);
  std::merge(p1.begin(), p1.end(), p2.begin(), p2.end(), std::back_inserter(pts));
  pts.push_back(b0);
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  double sum = 0.0;
  for (std::size_t k = 0; k + 1 < pts.size(); ++k) {
    const double a = pts[k], b = pts[k + 1];
    double fa = 0.0, fb = 0.0, ga = 0.0, gb = 0.0;
    linear_piece(*this, a, b, fa, fb);
    linear_piece(other, a, b, ga, gb);
    sum += (b - a) / 6.0 * (2.0 * fa * ga + fa * gb + fb * ga + 2.0 * fb * gb);
  }
  return sum;
}

std::vector<double> Spectrum::bin_averages(const BinLayout& bins) const {
  std::vector<double> out(static_cast<std::size_t>(bins.size()));
  for (int i = 0; i < bins.size(); ++i) out[i] = integrate(bins.lo_nm(i), bins.hi_nm(i)) / bins.width_nm(i);
  return out;
}

Spectrum Spectrum::resampled(const std::vector<double>& lambda_nm) const {
  std::vector<double> v(lambda_nm.size());
  for (std::size_t i = 0; i < lambda_nm.size(); ++i) v[i] = eval(lambda_nm[i]);
  return Spectrum(lambda_nm, std::move(v), "resampled wavelengths");
}

Spectrum Spectrum::scaled(double factor) const {
  if (!std::isfinite(factor)) {
    throw InputError("spectrum", "scale factor is not a finite number: " + format_double(factor));
  }
  Spectrum s = *this;
  s.m_constant_value *= factor;
  for (double& v : s.m_values) v *= factor;
  if (!std::isfinite(s.m_constant_value) || !std::all_of(s.m_values.begin(), s.m_values.end(), [](double v) {
        return std::isfinite(v);
      })) {
    throw InputError("spectrum", "scaling by " + format_double(factor) + " overflows");
  }
  return s;
}

double Spectrum::min_value() const {
  if (m_constant) return m_constant_value;
  if (m_values.empty()) return 0.0;
  return *std::min_element(m_values.begin(), m_values.end());
}

double Spectrum::max_value() const {
  if (m_constant) return m_constant_value;
  if (m_values.empty()) return 0.0;
  return *std::max_element(m_values.begin(), m_values.end());
}

double Spectrum::domain_lo_nm() const {
  if (m_constant) return -std::numeric_limits<double>::infinity();
  return m_lambda.empty() ? 0.0 : m_lambda.front();
}

double Spectrum::domain_hi_nm() const {
  if (m_constant) return std::numeric_limits<double>::infinity();
  return m_lambda.empty() ? 0.0 : m_lambda.back();
}

}  // namespace prizma::spectral
