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

// Diffuse reflection of a semi-infinite medium of albedo ω and any phase function p(cos Θ) (per
// steradian, normalised over the sphere), seen straight down (μ = 1) under a delta light of unit
// irradiance at μ0: I(1; μ0) = S(1, μ0)/(4π), where S is the azimuth average of Chandrasekhar's
// scattering function (Radiative Transfer, 1950, ch. IV, §27: the principle of invariance). At μ = 1
// the azimuth drops out, so S's m = 0 term is the whole answer, and it solves Ambartsumian's
// nonlinear equation, on its own for m = 0 (the azimuthal terms decouple):
//   (1/μ + 1/ν) S(μ, ν) = P−(μ, ν) + ½ ∫₀¹ S(μ, x) P+(x, ν) dx/x + ½ ∫₀¹ P+(μ, x) S(x, ν) dx/x
//                         + ¼ ∫₀¹∫₀¹ S(μ, x) P−(x, y) S(y, ν) dx/x dy/y,
// P±(a, b) = (1/2π) ∫₀^{2π} 4πω p(±ab + √(1−a²)√(1−b²) cos φ) dφ (the phase function between two
// upward directions, +, or an upward and a downward one, −). Solved by fixed-point iteration from 0
// (the orders of scattering) on 48 Gauss–Legendre nodes in μ, plus μ = 1 and μ0 as points of
// zero weight (Nyström), the azimuth by 48 nodes. Isotropic p gives ω μ ν H(μ) H(ν)/(μ + ν), checked
// against HFunction in test_render_directional.cpp.
class HalfSpaceReflection {
 public:
  HalfSpaceReflection(double albedo, const std::function<double(double)>& phase, double mu0) {
    gauss_legendre(kNodes, 0.0, 1.0, m_x, m_c);
    for (std::size_t i = 0; i < m_x.size(); ++i) m_c[i] /= m_x[i];  // the weights of dx/x
    m_x.push_back(1.0);
    m_x.push_back(mu0);
    m_c.push_back(0.0);
    m_c.push_back(0.0);
    const std::size_t n = m_x.size();
    std::vector<double> phi, wphi;
    gauss_legendre(kNodes, 0.0, std::numbers::pi, phi, wphi);  // p is even in φ: [0, π] is half the circle
    std::vector<double> plus(n * n), minus(n * n);
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t j = 0; j < n; ++j) {
        const double a = m_x[i], b = m_x[j], s = std::sqrt(std::max(0.0, (1.0 - a * a) * (1.0 - b * b)));
        double p = 0.0, m = 0.0;
        for (std::size_t k = 0; k < phi.size(); ++k) {
          p += wphi[k] * phase(std::clamp(a * b + s * std::cos(phi[k]), -1.0, 1.0));
          m += wphi[k] * phase(std::clamp(-a * b + s * std::cos(phi[k]), -1.0, 1.0));
        }
        plus[i * n + j] = 4.0 * albedo * p;  // 4πω · (1/π) ∫₀^π
        minus[i * n + j] = 4.0 * albedo * m;
      }
    m_s.assign(n * n, 0.0);
    std::vector<double> sc(n * n), cs(n * n), next(n * n);
    for (int it = 0; it < 5000; ++it) {
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < n; ++j) {
          sc[i * n + j] = m_s[i * n + j] * m_c[j];  // S·C
          cs[i * n + j] = m_c[i] * m_s[i * n + j];  // C·S
        }
      const std::vector<double> a = product(sc, plus, n), b = product(plus, cs, n);
      const std::vector<double> c = product(product(sc, minus, n), cs, n);
      double change = 0.0;
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < n; ++j) {
          const std::size_t k = i * n + j;
          next[k] = (minus[k] + 0.5 * a[k] + 0.5 * b[k] + 0.25 * c[k]) / (1.0 / m_x[i] + 1.0 / m_x[j]);
          change = std::max(change, std::abs(next[k] - m_s[k]));
        }
      m_s.swap(next);
      if (change < 1e-14) break;
    }
  }
  // The radiance seen straight down, S(1, μ0)/(4π).
  double radiance() const {
    const std::size_t n = m_x.size();
    return m_s[(n - 2) * n + (n - 1)] / (4.0 * std::numbers::pi);
  }

 private:
  static constexpr int kNodes = 48;
  static std::vector<double> product(const std::vector<double>& a, const std::vector<double>& b, std::size_t n) {
    std::vector<double> c(n * n, 0.0);
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t k = 0; k < n; ++k)
        for (std::size_t j = 0; j < n; ++j) c[i * n + j] += a[i * n + k] * b[k * n + j];
    return c;
  }
  std::vector<double> m_x, m_c, m_s;  // nodes (then 1 and μ0), weights of dx/x, S at the nodes
};

}  // namespace prizma::render::testing
