#include "prizma/spectral/light_design.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>

#include "design_solver.h"
#include "prizma/spectral/colour.h"
#include "prizma/spectral/error.h"

namespace prizma::spectral {

namespace {

std::string format_value(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

Eigen::VectorXd bin_vector(const Spectrum& s, const BinLayout& bins) {
  const std::vector<double> averages = s.bin_averages(bins);
  return Eigen::Map<const Eigen::VectorXd>(averages.data(), static_cast<Eigen::Index>(averages.size()));
}

void require_non_negative(const Spectrum& s, const std::string& input) {
  if (!(s.min_value() >= 0.0))
    throw InputError(input, "negative value " + format_value(s.min_value()) + " (a light or albedo must be >= 0)");
}

// Calls visit(w) for every point of the simplex grid {w : w_k = n_k / steps, Σ n_k = steps}.
void for_each_simplex_point(int size, int steps, const std::function<void(const Eigen::VectorXd&)>& visit) {
  Eigen::VectorXd w(size);
  std::vector<int> n(static_cast<size_t>(size), 0);
  const std::function<void(int, int)> recurse = [&](int index, int left) {
    if (index == size - 1) {
      n[static_cast<size_t>(index)] = left;
      for (int i = 0; i < size; ++i) w[i] = static_cast<double>(n[static_cast<size_t>(i)]) / steps;
      visit(w);
      return;
    }
    for (int v = 0; v <= left; ++v) {
      n[static_cast<size_t>(index)] = v;
      recurse(index + 1, left - v);
    }
  };
  recurse(0, steps);
}

}  // namespace

// long on purpose: one solve read in order (primaries, starts, projected ascent, power limit, result) sharing the tabulated XYZ.
LightDesignResult design_light(const Spectrum& albedo_a, const Spectrum& albedo_b, LightGoal goal,
                               const Spectrum& reference_light, const std::vector<Spectrum>& primaries,
                               const LightDesignOptions& options) {
  if (options.basis_size < 6 || options.basis_size > 200)
    throw InputError("options", "basis size " + std::to_string(options.basis_size) + " is outside [6, 200]");
  if (!(options.step_nm > 0.0)) throw InputError("options", "step_nm must be > 0");
  if (!(options.max_power_ratio >= 0.0)) throw InputError("options", "max_power_ratio must be >= 0");
  require_non_negative(albedo_a, "albedo-a");
  require_non_negative(albedo_b, "albedo-b");
  require_non_negative(reference_light, "reference light");
  const ColourSetting& colour = options.colour;
  const BinLayout& bins = colour.bins;
  const ColorMatching& cmf = ColorMatching::get(colour.observer);
  const double lo_nm = bins.min_nm();
  const double hi_nm = bins.max_nm();

  // The working primaries: the user's, resampled every 1 nm over the bins' range (so the output mix
  // is exactly what was optimised), or a B-spline basis for a free-form light.
  std::vector<Spectrum> working;
  if (primaries.empty()) {
    const std::vector<double> lambda = detail::design_grid(lo_nm, hi_nm, options.step_nm);
    const int nodes = static_cast<int>(lambda.size());
    const Eigen::VectorXd lambda_vec = Eigen::Map<const Eigen::VectorXd>(lambda.data(), nodes);
    const Eigen::MatrixXd basis = detail::bspline_basis(lambda_vec, lo_nm, hi_nm, options.basis_size);
    for (int j = 0; j < options.basis_size; ++j) {
      const Eigen::VectorXd column = basis.col(j);
      working.emplace_back(lambda, std::vector<double>(column.data(), column.data() + nodes), "light basis");
    }
  } else {
    std::vector<double> lambda;
    for (double l = lo_nm; l < hi_nm; l += 1.0) lambda.push_back(l);
    if (lambda.back() < hi_nm) lambda.push_back(hi_nm);
    for (size_t i = 0; i < primaries.size(); ++i) {
      const std::string input = "primaries[" + std::to_string(i) + "]";
      require_non_negative(primaries[i], input);
      const Spectrum sampled = primaries[i].resampled(lambda);
      working.push_back(sampled);
    }
  }
  const int k = static_cast<int>(working.size());

  // Per primary: XYZ of each albedo and of a perfect white, in absolute units so that mixes add.
  const Eigen::VectorXd pa = bin_vector(albedo_a, bins);
  const Eigen::VectorXd pb = bin_vector(albedo_b, bins);
  Eigen::MatrixXd xa(3, k), xb(3, k), white(3, k);
  for (int j = 0; j < k; ++j) {
    Eigen::Matrix<double, 3, Eigen::Dynamic> m;
    try {
      m = relight_weights(cmf, working[static_cast<size_t>(j)], bins, LightUnits::Absolute);
    } catch (const InputError& e) {
      throw InputError(primaries.empty() ? "light basis" : "primaries[" + std::to_string(j) + "]", e.reason());
    }
    xa.col(j) = m * pa;
    xb.col(j) = m * pb;
    white.col(j) = m.rowwise().sum();
  }
  double reference_luminance = 0.0;
  try {
    reference_luminance = relight_weights(cmf, reference_light, bins, LightUnits::Absolute).row(1).sum();
  } catch (const InputError& e) {
    throw InputError("reference light", e.reason());
  }

  const auto delta_e = [&](const Eigen::VectorXd& w) {
    const Eigen::Vector3d w_xyz = white * w;
    if (!(w_xyz.y() > 1e-12 * white.row(1).cwiseAbs().sum())) return std::numeric_limits<double>::quiet_NaN();
    return delta_e2000(xyz_to_lab(xa * w, w_xyz), xyz_to_lab(xb * w, w_xyz));
  };
  const Eigen::MatrixXd difference = xa - xb;
  if (goal == LightGoal::Reveal && difference.cwiseAbs().maxCoeff() <= 1e-9 * xa.cwiseAbs().maxCoeff())
    throw InputError("albedo-b", "has the same colour as albedo-a under every light of the search: nothing to reveal");

  // Starts: the reference light's shape in the basis (non-negative least squares by clipping), the
  // best point of a simplex grid over few primaries, and each primary alone.
  std::vector<Eigen::VectorXd> starts;
  {
    Eigen::VectorXd fit;
    if (primaries.empty()) {
      const Spectrum& first = working.front();
      const std::vector<double>& lambda = first.wavelengths_nm();
      Eigen::MatrixXd basis(static_cast<Eigen::Index>(lambda.size()), k);
      Eigen::VectorXd samples(static_cast<Eigen::Index>(lambda.size()));
      for (size_t i = 0; i < lambda.size(); ++i) {
        samples[static_cast<Eigen::Index>(i)] = reference_light.eval(lambda[i]);
        for (int j = 0; j < k; ++j) basis(static_cast<Eigen::Index>(i), j) = working[static_cast<size_t>(j)].values()[i];
      }
      fit = basis.colPivHouseholderQr().solve(samples).cwiseMax(0.0);
    } else {
      fit = Eigen::VectorXd::Ones(k);
    }
    if (fit.maxCoeff() > 0.0) starts.push_back(fit / fit.maxCoeff());
  }
  const double sign = goal == LightGoal::Reveal ? 1.0 : -1.0;
  const auto objective = [&](const Eigen::VectorXd& w) {
    const double v = delta_e(w);
    return std::isfinite(v) ? sign * v : -std::numeric_limits<double>::infinity();
  };
  const int grid_steps[] = {0, 1, 200, 60, 30, 18, 12};
  if (!primaries.empty() && k <= 6) {
    Eigen::VectorXd grid_best;
    double grid_value = -std::numeric_limits<double>::infinity();
    for_each_simplex_point(k, grid_steps[k], [&](const Eigen::VectorXd& w) {
      const double v = objective(w);
      if (v > grid_value) {
        grid_value = v;
        grid_best = w;
      }
    });
    if (grid_best.size() == k) starts.push_back(grid_best / grid_best.maxCoeff());
  }
  for (int j = 0; j < k; ++j) starts.push_back(Eigen::VectorXd::Unit(k, j));

  // The search: projected ascent over the box [0, 1]^k (ΔE00 in CIELAB relative to the light's own
  // white does not change with the light's scale, so the box only fixes the scale).
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(k);
  const Eigen::VectorXd one = Eigen::VectorXd::Ones(k);
  // The power limit is the half-space (power − ratio·P_ref/Y_ref·luminance)·w ≤ 0.
  Eigen::MatrixXd power_row(1, k);
  for (int j = 0; j < k; ++j) power_row(0, j) = working[static_cast<size_t>(j)].integrate(lo_nm, hi_nm);
  const double reference_power = reference_light.integrate(lo_nm, hi_nm);
  const bool limit_power = options.max_power_ratio > 0.0 && reference_power > 0.0;
  if (limit_power) power_row -= (options.max_power_ratio * reference_power / reference_luminance) * white.row(1);
  const auto project_box = [&](const Eigen::VectorXd& w) -> std::optional<Eigen::VectorXd> {
    Eigen::VectorXd c = w.cwiseMax(zero).cwiseMin(one);
    if (limit_power && (power_row * c)(0) > 0.0) {
      const std::optional<Eigen::VectorXd> p = detail::project_box_affine(power_row, Eigen::VectorXd::Zero(1), c, zero, one);
      if (!p) return std::nullopt;
      c = *p;
    }
    if (!(c.maxCoeff() > 0.0)) return std::nullopt;
    return c;
  };
  std::optional<detail::AscentResult> found;
  for (const Eigen::VectorXd& s : starts) {
    const std::optional<Eigen::VectorXd> start = project_box(s);
    if (!start) continue;
    const detail::AscentResult r = detail::projected_ascent(objective, project_box, *start, options.iterations, 0.25);
    if (!found || r.value > found->value) found = r;
  }
  if (!found) throw InputError("primaries", "no mix of them satisfies the power limit (max_power_ratio)");
  detail::AscentResult best = *found;

  // Hiding: the light closest to the reference's shape under which both albedos have exactly the same
  // XYZ, when one exists (projection onto {w ≥ 0, (XYZ_a − XYZ_b)·w = 0, Y_white·w = Y_ref}).
  if (goal == LightGoal::Hide) {
    Eigen::MatrixXd a(4, k);
    a.topRows(3) = difference;
    a.row(3) = white.row(1);
    Eigen::VectorXd b = Eigen::VectorXd::Zero(4);
    b[3] = 1.0;
    const Eigen::VectorXd scale = starts.front() / std::max(1e-300, white.row(1).dot(starts.front()));
    const std::optional<Eigen::VectorXd> exact = detail::project_box_affine(
        a, b, scale, zero, Eigen::VectorXd::Constant(k, std::numeric_limits<double>::infinity()), 1e-12);
    if (exact && exact->maxCoeff() > 0.0) {
      const Eigen::VectorXd w = *exact / exact->maxCoeff();
      const double v = objective(w);
      if (v >= best.value - 1e-6) best = {w, v};
    }
  }

  // The output: the mix scaled to the reference luminance, verified from the tabulated spectrum.
  Eigen::VectorXd w = best.x;
  const double luminance = white.row(1).dot(w);
  if (!(luminance > 0.0)) throw RuntimeError("light design found no light with luminance in the bins");
  w *= reference_luminance / luminance;
  const std::vector<double>& lambda = working.front().wavelengths_nm();
  std::vector<double> values(lambda.size(), 0.0);
  for (int j = 0; j < k; ++j)
    for (size_t i = 0; i < lambda.size(); ++i) values[i] += w[j] * working[static_cast<size_t>(j)].values()[i];
  for (double& v : values) v = std::max(0.0, v);
  LightDesignResult result;
  result.light = Spectrum(lambda, values, "designed light");
  result.weights.assign(w.data(), w.data() + k);
  result.delta_e = delta_e2000_under(albedo_a, albedo_b, result.light, colour);
  result.delta_e_reference = delta_e2000_under(albedo_a, albedo_b, reference_light, colour);
  return result;
}

}  // namespace prizma::spectral
