#include "prizma/spectral/metamer_design.h"

#include <Eigen/QR>
#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "design_solver.h"
#include "prizma/spectral/colour.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/spectrum_spec.h"

namespace prizma::spectral {

namespace {

Eigen::Matrix<double, 3, Eigen::Dynamic> weights_for(const Spectrum& light, const ColourSetting& colour,
                                                     const std::string& input) {
  try {
    return relight_weights(ColorMatching::get(colour.observer), light, colour.bins);
  } catch (const InputError& e) {
    throw InputError(input, e.reason());
  }
}

Eigen::VectorXd bin_vector(const Spectrum& s, const BinLayout& bins) {
  const std::vector<double> averages = s.bin_averages(bins);
  return Eigen::Map<const Eigen::VectorXd>(averages.data(), static_cast<Eigen::Index>(averages.size()));
}

std::string format_value(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

}  // namespace

Eigen::Vector3d reflectance_xyz(const Spectrum& reflectance, const Spectrum& light, const ColourSetting& colour) {
  return weights_for(light, colour, "light") * bin_vector(reflectance, colour.bins);
}

double delta_e2000_under(const Spectrum& a, const Spectrum& b, const Spectrum& light, const ColourSetting& colour) {
  const Eigen::Matrix<double, 3, Eigen::Dynamic> m = weights_for(light, colour, "light");
  const Eigen::Vector3d white = m.rowwise().sum();
  return delta_e2000(xyz_to_lab(m * bin_vector(a, colour.bins), white),
                     xyz_to_lab(m * bin_vector(b, colour.bins), white));
}

std::vector<NamedLight> standard_report_lights() {
  std::vector<NamedLight> lights;
  for (const char* name : {"D65", "A", "F2", "F11", "LED-B3"}) lights.push_back({name, parse_spectrum(name)});
  return lights;
}

// long on purpose: one solve read in order (checks, basis, start, the 26 Lab directions, verification) sharing the tabulated maps.
MetamerResult design_metamer(const Spectrum& albedo, const Spectrum& match_light, const Spectrum& split_light,
                             const MetamerOptions& options) {
  // Options.
  if (options.basis_size < 6 || options.basis_size > 200)
    throw InputError("options", "basis size " + std::to_string(options.basis_size) + " is outside [6, 200]");
  if (!(options.step_nm > 0.0) || !(options.min_value >= 0.0) || !(options.max_value <= 1.0) ||
      !(options.min_value < options.max_value))
    throw InputError("options", "need step_nm > 0 and 0 <= min_value < max_value <= 1 (got step " +
                                    format_value(options.step_nm) + ", bounds " + format_value(options.min_value) +
                                    ".." + format_value(options.max_value) + ")");
  const BinLayout& bins = options.colour.bins;
  const double lo_nm = bins.min_nm();
  const double hi_nm = bins.max_nm();

  // The albedo must itself be a valid reflectance within the bounds where the colour is computed.
  {
    std::vector<double> probe;
    for (double l = lo_nm; l < hi_nm; l += 1.0) probe.push_back(l);
    probe.push_back(hi_nm);
    for (double l : albedo.wavelengths_nm())
      if (l >= lo_nm && l <= hi_nm) probe.push_back(l);
    for (double l : probe) {
      const double v = albedo.eval(l);
      if (!(v >= options.min_value - 1e-9 && v <= options.max_value + 1e-9))
        throw InputError("albedo", "value " + format_value(v) + " at " + format_value(l) + " nm is outside [" +
                                       format_value(options.min_value) + ", " + format_value(options.max_value) +
                                       "]");
    }
  }

  const Eigen::Matrix<double, 3, Eigen::Dynamic> m1 = weights_for(match_light, options.colour, "match light");
  const Eigen::Matrix<double, 3, Eigen::Dynamic> m2 = weights_for(split_light, options.colour, "split light");
  const Eigen::Vector3d white2 = m2.rowwise().sum();

  // The basis tabulated on the output grid; its bin averages give the linear maps coefficient → XYZ.
  const std::vector<double> lambda = detail::design_grid(lo_nm, hi_nm, options.step_nm);
  const int nodes = static_cast<int>(lambda.size());
  const Eigen::VectorXd lambda_vec = Eigen::Map<const Eigen::VectorXd>(lambda.data(), nodes);
  const int k = options.basis_size;
  const Eigen::MatrixXd basis = detail::bspline_basis(lambda_vec, lo_nm, hi_nm, k);
  Eigen::MatrixXd averages(bins.size(), k);
  for (int j = 0; j < k; ++j) {
    const Eigen::VectorXd column = basis.col(j);
    averages.col(j) = bin_vector(Spectrum(lambda, std::vector<double>(column.data(), column.data() + nodes)), bins);
  }
  const Eigen::MatrixXd g1 = m1 * averages;
  const Eigen::MatrixXd g2 = m2 * averages;
  const Eigen::Vector3d target1 = m1 * bin_vector(albedo, bins);
  const Eigen::Vector3d lab2_ref = xyz_to_lab(m2 * bin_vector(albedo, bins), white2);

  const Eigen::VectorXd lo = Eigen::VectorXd::Constant(k, options.min_value);
  const Eigen::VectorXd hi = Eigen::VectorXd::Constant(k, options.max_value);
  const auto project = [&](const Eigen::VectorXd& c) {
    return detail::project_box_affine(g1, target1, c, lo, hi);
  };

  // Start: the least-squares fit of the albedo in the basis, projected onto the feasible set.
  Eigen::VectorXd samples(nodes);
  for (int j = 0; j < nodes; ++j) samples[j] = albedo.eval(lambda[j]);
  const Eigen::VectorXd fit = basis.colPivHouseholderQr().solve(samples);
  const std::optional<Eigen::VectorXd> start = project(fit);
  if (!start)
    throw InputError("albedo", "no smooth reflectance within [" + format_value(options.min_value) + ", " +
                                   format_value(options.max_value) + "] has its colour under the match light");

  const auto lab2 = [&](const Eigen::VectorXd& c) { return xyz_to_lab(g2 * c, white2); };
  const auto split_delta_e = [&](const Eigen::VectorXd& c) { return delta_e2000(lab2(c), lab2_ref); };

  // Directions in Lab: the 26 non-zero points of {−1, 0, 1}³ (axes first). For each, push the
  // split-light colour along it (linear objective), then climb ΔE00 itself; keep the best.
  std::vector<Eigen::Vector3d> directions;
  for (int pass = 1; pass <= 3; ++pass)
    for (int dl = -1; dl <= 1; ++dl)
      for (int da = -1; da <= 1; ++da)
        for (int db = -1; db <= 1; ++db)
          if (std::abs(dl) + std::abs(da) + std::abs(db) == pass)
            directions.push_back(Eigen::Vector3d(dl, da, db).normalized());
  const int direction_count = std::clamp(options.directions, 1, static_cast<int>(directions.size()));
  detail::AscentResult best{*start, split_delta_e(*start)};
  for (int d = 0; d < direction_count; ++d) {
    const Eigen::Vector3d dir = directions[static_cast<size_t>(d)];
    const auto along = [&](const Eigen::VectorXd& c) { return dir.dot(lab2(c) - lab2_ref); };
    const detail::AscentResult pushed =
        detail::projected_ascent(along, project, *start, std::max(1, options.iterations / 3));
    const detail::AscentResult climbed = detail::projected_ascent(split_delta_e, project, pushed.x, options.iterations);
    if (climbed.value > best.value) best = climbed;
  }

  // The metamer on the output grid (clamping only removes rounding), verified from the tabulated result.
  const Eigen::VectorXd values = (basis * best.x).cwiseMax(options.min_value).cwiseMin(options.max_value);
  MetamerResult result;
  result.reflectance = Spectrum(lambda, std::vector<double>(values.data(), values.data() + nodes), "metamer");
  result.delta_e_match = delta_e2000_under(albedo, result.reflectance, match_light, options.colour);
  result.delta_e_split = delta_e2000_under(albedo, result.reflectance, split_light, options.colour);
  if (!(result.delta_e_split >= options.min_split_delta_e))
    throw InputError("albedo", "no smooth metamer within the bounds differs from it by ΔE00 >= " +
                                   format_value(options.min_split_delta_e) + " under the split light (best " +
                                   format_value(result.delta_e_split) + ")");
  return result;
}

}  // namespace prizma::spectral
