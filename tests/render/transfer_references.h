#pragma once
// Independent references of the renderer's closed-form tests: Gauss–Legendre quadrature, the
// Henyey–Greenstein phase function written out, and Chandrasekhar's H-function. None of it calls the
// renderer, so a test that compares a render with these checks the renderer, not itself.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <functional>
#include <numbers>
#include <vector>

namespace prizma::render::testing {

// Gauss–Legendre nodes x and weights w of n points on [a, b] (Newton on P_n from the Chebyshev
// guesses; exact for polynomials of degree ≤ 2n − 1).
inline void gauss_legendre(int n, double a, double b, std::vector<double>& x, std::vector<double>& w) {
  x.assign(n, 0.0);
  w.assign(n, 0.0);
  for (int i = 0; i < n; ++i) {
    double z = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5)), dp = 0.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (z * p1 - p0) / (z * z - 1.0);
      const double dz = p1 / dp;
      z -= dz;
      if (std::abs(dz) < 1e-15) break;
    }
    x[i] = 0.5 * (a + b) - 0.5 * (b - a) * z;
    w[i] = (b - a) / ((1.0 - z * z) * dp * dp);
  }
}

// ∫_a^b f by n-point Gauss–Legendre.
inline double integrate(const std::function<double(double)>& f, double a, double b, int n = 96) {
  std::vector<double> x, w;
  gauss_legendre(n, a, b, x, w);
  double s = 0.0;
  for (int i = 0; i < n; ++i) s += w[i] * f(x[i]);
  return s;
}

// The Henyey–Greenstein phase function per steradian (normalised over the sphere).
inline double hg(double cos_theta, double g) {
  return (1.0 - g * g) / (4.0 * std::numbers::pi * std::pow(1.0 + g * g - 2.0 * g * cos_theta, 1.5));
}

// Chandrasekhar's H-function for isotropic scattering of albedo ω (Radiative Transfer, 1950, ch. V),
// by the standard fixed-point iteration of its equivalent form
//   1/H(μ) = √(1 − ω) + (ω/2) ∫₀¹ μ' H(μ') / (μ + μ') dμ'
// on 64 Gauss–Legendre nodes (Nyström: H at any μ from the converged nodal values).
// test_render_directional.cpp checks it against the H-equation and its zeroth moment.
class HFunction {
 public:
  explicit HFunction(double albedo) : m_w(albedo) {
    gauss_legendre(64, 0.0, 1.0, m_x, m_q);
    m_h.assign(m_x.size(), 1.0);
    for (int it = 0; it < 500; ++it) {
      double change = 0.0;
      std::vector<double> next(m_x.size());
      for (std::size_t i = 0; i < m_x.size(); ++i) {
        next[i] = (*this)(m_x[i]);
        change = std::max(change, std::abs(next[i] - m_h[i]));
      }
      m_h = next;
      if (change < 1e-14) break;
    }
  }
  double operator()(double mu) const {
    double s = 0.0;
    for (std::size_t j = 0; j < m_x.size(); ++j) s += m_q[j] * m_x[j] * m_h[j] / (mu + m_x[j]);
    return 1.0 / (std::sqrt(1.0 - m_w) + 0.5 * m_w * s);
  }
  // ∫₀¹ H dμ, whose exact value is (2/ω)(1 − √(1 − ω)) (Chandrasekhar's zeroth moment).
  double moment0() const {
    double s = 0.0;
    for (std::size_t j = 0; j < m_x.size(); ++j) s += m_q[j] * m_h[j];
    return s;
  }

 private:
  double m_w;
  std::vector<double> m_x, m_q, m_h;
};

}  // namespace prizma::render::testing
