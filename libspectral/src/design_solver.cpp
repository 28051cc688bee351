#include "design_solver.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace prizma::spectral::detail {

std::optional<Eigen::VectorXd> project_box_affine(const Eigen::MatrixXd& a, const Eigen::VectorXd& b,
                                                  const Eigen::VectorXd& y, const Eigen::VectorXd& lo,
                                                  const Eigen::VectorXd& hi, double tolerance) {
  const Eigen::Index m = a.rows();
  if (m == 0) return y.cwiseMax(lo).cwiseMin(hi);
  const auto x_of = [&](const Eigen::VectorXd& mu) -> Eigen::VectorXd {
    return (y + a.transpose() * mu).cwiseMax(lo).cwiseMin(hi);
  };
  // The dual objective q(μ) = ½‖x(μ) − y‖² − μᵀ(A·x(μ) − b): concave, gradient b − A·x(μ).
  const auto dual = [&](const Eigen::VectorXd& mu, const Eigen::VectorXd& x) {
    return 0.5 * (x - y).squaredNorm() - mu.dot(a * x - b);
  };
  const double scale = std::max(1.0, (a * a.transpose()).trace() / static_cast<double>(m));
  const double limit = tolerance * (1.0 + b.norm());
  Eigen::VectorXd mu = Eigen::VectorXd::Zero(m);
  for (int iteration = 0; iteration < 500; ++iteration) {
    const Eigen::VectorXd x = x_of(mu);
    const Eigen::VectorXd residual = b - a * x;
    if (residual.norm() <= limit) return x;
    // Semismooth Newton step: the generalised Hessian is −A·D·Aᵀ with D the free (unclipped) set.
    const Eigen::VectorXd unclipped = y + a.transpose() * mu;
    Eigen::VectorXd free = Eigen::VectorXd::Zero(y.size());
    for (Eigen::Index i = 0; i < y.size(); ++i) free[i] = (unclipped[i] > lo[i] && unclipped[i] < hi[i]) ? 1.0 : 0.0;
    Eigen::MatrixXd h = a * free.asDiagonal() * a.transpose();
    h.diagonal().array() += 1e-10 * scale;
    const Eigen::VectorXd step = h.ldlt().solve(residual);
    if (!step.allFinite()) return std::nullopt;
    // Backtracking (Armijo) on the concave dual.
    const double q0 = dual(mu, x);
    const double slope = residual.dot(step);
    double t = 1.0;
    bool accepted = false;
    Eigen::VectorXd next;
    while (t > 1e-14) {
      next = mu + t * step;
      if (dual(next, x_of(next)) >= q0 + 1e-6 * t * slope) {
        accepted = true;
        break;
      }
      t *= 0.5;
    }
    if (!accepted) return std::nullopt;
    mu = next;
    // A diverging multiplier means the dual is unbounded: the constraint set is empty.
    if (!mu.allFinite() || mu.norm() > 1e12) return std::nullopt;
  }
  return std::nullopt;
}

AscentResult projected_ascent(const std::function<double(const Eigen::VectorXd&)>& f,
                              const std::function<std::optional<Eigen::VectorXd>(const Eigen::VectorXd&)>& project,
                              const Eigen::VectorXd& x0, int iterations, double initial_step, double h) {
  AscentResult best{x0, f(x0)};
  if (!std::isfinite(best.value)) best.value = -std::numeric_limits<double>::infinity();
  double step = initial_step;
  Eigen::VectorXd gradient(x0.size());
  for (int iteration = 0; iteration < iterations && step > 1e-5; ++iteration) {
    // Central differences; a non-finite side gives a zero component.
    for (Eigen::Index i = 0; i < x0.size(); ++i) {
      Eigen::VectorXd plus = best.x, minus = best.x;
      plus[i] += h;
      minus[i] -= h;
      const double d = (f(plus) - f(minus)) / (2.0 * h);
      gradient[i] = std::isfinite(d) ? d : 0.0;
    }
    const double norm = gradient.lpNorm<Eigen::Infinity>();
    if (!(norm > 0.0)) break;
    const std::optional<Eigen::VectorXd> candidate = project(best.x + (step / norm) * gradient);
    const double value = candidate ? f(*candidate) : -std::numeric_limits<double>::infinity();
    if (candidate && std::isfinite(value) && value > best.value) {
      best = {*candidate, value};
      step = std::min(initial_step, step * 1.5);
    } else {
      step *= 0.5;
    }
  }
  return best;
}

Eigen::MatrixXd bspline_basis(const Eigen::VectorXd& x, double lo, double hi, int count) {
  constexpr int kDegree = 3;
  const int spans = count - kDegree;
  // Clamped knot vector: lo repeated 4×, uniform interior knots, hi repeated 4×.
  std::vector<double> knots;
  for (int i = 0; i < kDegree; ++i) knots.push_back(lo);
  for (int i = 0; i <= spans; ++i) knots.push_back(lo + (hi - lo) * i / spans);
  for (int i = 0; i < kDegree; ++i) knots.push_back(hi);
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(x.size(), count);
  for (Eigen::Index p = 0; p < x.size(); ++p) {
    const double t = std::clamp(x[p], lo, hi);
    // Cox–de Boor recursion on the degree-0 indicator of the span holding t (the last span closed).
    std::vector<double> n(knots.size() - 1, 0.0);
    for (size_t i = 0; i + 1 < knots.size(); ++i) {
      const bool last = (t == hi) && knots[i] < hi && knots[i + 1] == hi;
      n[i] = ((knots[i] <= t && t < knots[i + 1]) || last) ? 1.0 : 0.0;
    }
    for (int d = 1; d <= kDegree; ++d) {
      for (size_t i = 0; i + d + 1 < knots.size(); ++i) {
        double value = 0.0;
        const double left = knots[i + d] - knots[i];
        const double right = knots[i + d + 1] - knots[i + 1];
        if (left > 0.0) value += (t - knots[i]) / left * n[i];
        if (right > 0.0) value += (knots[i + d + 1] - t) / right * n[i + 1];
        n[i] = value;
      }
    }
    for (int j = 0; j < count; ++j) out(p, j) = n[j];
  }
  return out;
}

std::vector<double> design_grid(double lo_nm, double hi_nm, double step_nm) {
  const int nodes = std::max(2, static_cast<int>(std::lround((hi_nm - lo_nm) / step_nm)) + 1);
  std::vector<double> lambda(static_cast<std::size_t>(nodes));
  for (int j = 0; j < nodes; ++j) lambda[j] = (j == nodes - 1) ? hi_nm : lo_nm + (hi_nm - lo_nm) * j / (nodes - 1);
  return lambda;
}

}  // namespace prizma::spectral::detail
