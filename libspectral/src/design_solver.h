#pragma once
// Small constrained solvers shared by the metamer and light design (internal to libspectral).
#include <Eigen/Core>
#include <functional>
#include <optional>
#include <vector>

namespace prizma::spectral::detail {

// Euclidean projection of y onto {x : A·x = b, lo ≤ x ≤ hi} (hi may be +inf). Solved through the
// concave dual in the m multipliers of the equalities (x(μ) = clip(y + Aᵀμ, lo, hi)) by a damped
// semismooth Newton method. Returns nullopt when the set is empty (the dual diverges) or the
// residual ‖A·x − b‖ does not fall below tolerance·(1 + ‖b‖).
std::optional<Eigen::VectorXd> project_box_affine(const Eigen::MatrixXd& a, const Eigen::VectorXd& b,
                                                  const Eigen::VectorXd& y, const Eigen::VectorXd& lo,
                                                  const Eigen::VectorXd& hi, double tolerance = 1e-10);

// Projected gradient ascent of f over a feasible set given by `project` (which returns nullopt when it
// fails). The gradient is taken by central differences of step `h`; steps are normalised to a
// maximum-norm length that starts at `initial_step` and halves whenever a step does not improve f.
// Returns the best point visited (x0 itself when nothing improves).
struct AscentResult {
  Eigen::VectorXd x;
  double value = 0.0;
};
AscentResult projected_ascent(const std::function<double(const Eigen::VectorXd&)>& f,
                              const std::function<std::optional<Eigen::VectorXd>(const Eigen::VectorXd&)>& project,
                              const Eigen::VectorXd& x0, int iterations, double initial_step = 0.5,
                              double h = 1e-6);

// Clamped uniform cubic B-spline basis with `count` functions over [lo, hi], evaluated at `x`
// (rows: points, columns: functions). Every row sums to 1 and every entry is in [0, 1], so
// coefficients in [0, 1] give a curve in [0, 1] (convex hull property).
Eigen::MatrixXd bspline_basis(const Eigen::VectorXd& x, double lo, double hi, int count);

// Evenly spaced wavelengths from lo to hi (both included, the last exactly hi) about step apart,
// at least 2: the output grid of the designed spectra.
std::vector<double> design_grid(double lo_nm, double hi_nm, double step_nm);

}  // namespace prizma::spectral::detail
