// Spectral basis of a transport layer (spectral_basis.h): Gram matrix in fixed pixel blocks, its
// self-adjoint eigendecomposition, projections and the ΔE00-driven choice of k.
#include "prizma/spectral/spectral_basis.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "prizma/spectral/colour.h"
#include "prizma/spectral/error.h"

namespace prizma::spectral {

namespace {

constexpr std::size_t kGramBlock = 4096;  // pixels per GEMM block

void check_shape(std::size_t pixels, int n) {
  if (n < 1) throw InputError("spectral basis", "needs at least one bin");
  if (pixels == 0) throw InputError("spectral basis", "needs at least one pixel");
}

// The pixels evaluated by the criterion: all, or max_samples evenly strided ones.
std::vector<std::size_t> sample_pixels(std::size_t pixels, std::size_t max_samples) {
  const std::size_t count = (max_samples == 0 || pixels <= max_samples) ? pixels : max_samples;
  std::vector<std::size_t> out(count);
  for (std::size_t i = 0; i < count; ++i) out[i] = static_cast<std::size_t>((static_cast<double>(i) + 0.5) *
                                                                             static_cast<double>(pixels) /
                                                                             static_cast<double>(count));
  return out;
}

// Nearest-rank percentile of unsorted values (q in [0, 100]).
double percentile_of(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  const double rank = std::ceil(q / 100.0 * static_cast<double>(values.size()));
  const std::size_t i = static_cast<std::size_t>(std::clamp(rank, 1.0, static_cast<double>(values.size()))) - 1;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(i), values.end());
  return values[i];
}

// Per test light: its 3×n weights, its white and the exact Lab of every sampled pixel.
struct TestLight {
  std::string name;
  Eigen::Matrix<double, 3, Eigen::Dynamic> weights;
  Eigen::Vector3d white;
  std::vector<Eigen::Vector3d> exact_lab;
};

std::vector<TestLight> prepare_lights(const float* data, int n, const std::vector<std::size_t>& samples,
                                      const BinLayout& bins, const BasisCriterion& criterion) {
  if (bins.size() != n) {
    throw InputError("spectral basis", "bin layout has " + std::to_string(bins.size()) + " bins, data has " +
                                           std::to_string(n));
  }
  const ColorMatching& cmf = ColorMatching::get(criterion.cmf);
  std::vector<TestLight> out;
  for (const std::string& spec : criterion.lights) {
    TestLight light;
    light.name = spec;
    light.weights = relight_weights(cmf, parse_light_spectrum(spec), bins);
    light.white = light.weights.rowwise().sum().cwiseMax(1e-9);
    light.exact_lab.reserve(samples.size());
    for (std::size_t p : samples) {
      const Eigen::Map<const Eigen::VectorXf> t(data + p * static_cast<std::size_t>(n), n);
      light.exact_lab.push_back(xyz_to_lab(light.weights * t.cast<double>(), light.white));
    }
    out.push_back(std::move(light));
  }
  return out;
}

// ΔE00 of each test light's relit reconstruction at every sample, against the exact: `weights(w_l)`
// gives the 3×m matrix from the light's 3×n weights and `vector(i)` sample i's m values (the
// spectrum, or its coefficients), as floats.
template <class Weights, class Vector>
std::vector<BasisError> errors_of(const std::vector<TestLight>& lights, std::size_t samples, double q, Weights weights,
                                  Vector vector) {
  std::vector<BasisError> out;
  std::vector<double> de(samples);
  for (const TestLight& light : lights) {
    const Eigen::Matrix<double, 3, Eigen::Dynamic> w = weights(light.weights);
    double worst = 0.0;
    for (std::size_t i = 0; i < samples; ++i) {
      de[i] = delta_e2000(light.exact_lab[i], xyz_to_lab(w * vector(i).template cast<double>(), light.white));
      worst = std::max(worst, de[i]);
    }
    out.push_back({light.name, percentile_of(de, q), worst});
  }
  return out;
}

std::vector<BasisError> errors_at(const SpectralBasis& basis, int k, const float* data, int n,
                                  const std::vector<std::size_t>& samples, const std::vector<TestLight>& lights,
                                  double q) {
  const Eigen::MatrixXd bk = basis.vectors.leftCols(k);
  const Eigen::MatrixXd projector = bk * bk.transpose();
  return errors_of(
      lights, samples.size(), q, [&](const Eigen::Matrix<double, 3, Eigen::Dynamic>& w) { return w * projector; },
      [&](std::size_t i) { return Eigen::Map<const Eigen::VectorXf>(data + samples[i] * static_cast<std::size_t>(n), n); });
}

}  // namespace

Eigen::MatrixXd spectral_gram(const float* data, std::size_t pixels, int n) {
  check_shape(pixels, n);
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(n, n);
  Eigen::MatrixXd block(n, static_cast<Eigen::Index>(kGramBlock));
  for (std::size_t first = 0; first < pixels; first += kGramBlock) {
    const std::size_t count = std::min(kGramBlock, pixels - first);
    const Eigen::Map<const Eigen::MatrixXf> x(data + first * static_cast<std::size_t>(n), n,
                                              static_cast<Eigen::Index>(count));
    block.leftCols(static_cast<Eigen::Index>(count)) = x.cast<double>();
    const auto b = block.leftCols(static_cast<Eigen::Index>(count));
    gram.noalias() += b * b.transpose();
  }
  return gram;
}

SpectralBasis spectral_basis(const float* data, std::size_t pixels, int n) {
  const Eigen::MatrixXd gram = spectral_gram(data, pixels, n);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(gram);
  if (solver.info() != Eigen::Success) throw RuntimeError("spectral basis: eigendecomposition did not converge");
  SpectralBasis basis;
  basis.vectors.resize(n, n);
  basis.singular_values.resize(n);
  // Eigen returns increasing eigenvalues: reverse, clamp rounding negatives, fix the signs.
  for (int j = 0; j < n; ++j) {
    const int src = n - 1 - j;
    Eigen::VectorXd v = solver.eigenvectors().col(src);
    Eigen::Index big = 0;
    v.cwiseAbs().maxCoeff(&big);
    if (v[big] < 0.0) v = -v;
    basis.vectors.col(j) = v;
    basis.singular_values[j] = std::sqrt(std::max(0.0, solver.eigenvalues()[src]));
  }
  return basis;
}

std::vector<float> project_coefficients(const SpectralBasis& basis, int k, const float* data, std::size_t pixels) {
  const int n = basis.bins();
  if (k < 1 || k > n) throw InputError("spectral basis", "k = " + std::to_string(k) + " is outside 1.." + std::to_string(n));
  const Eigen::MatrixXf bt = basis_columns(basis, k).transpose();
  std::vector<float> out(pixels * static_cast<std::size_t>(k));
  const Eigen::Map<const Eigen::MatrixXf> x(data, n, static_cast<Eigen::Index>(pixels));
  Eigen::Map<Eigen::MatrixXf> c(out.data(), k, static_cast<Eigen::Index>(pixels));
  for (std::size_t first = 0; first < pixels; first += kGramBlock) {
    const auto count = static_cast<Eigen::Index>(std::min(kGramBlock, pixels - first));
    const auto f = static_cast<Eigen::Index>(first);
    c.middleCols(f, count).noalias() = bt * x.middleCols(f, count);
  }
  return out;
}

Eigen::MatrixXf basis_columns(const SpectralBasis& basis, int k) {
  return basis.vectors.leftCols(k).cast<float>();
}

std::vector<BasisError> basis_errors(const SpectralBasis& basis, int k, const float* data, std::size_t pixels,
                                     const BinLayout& bins, const BasisCriterion& criterion) {
  const int n = basis.bins();
  if (k < 1 || k > n) throw InputError("spectral basis", "k = " + std::to_string(k) + " is outside 1.." + std::to_string(n));
  const auto samples = sample_pixels(pixels, criterion.max_samples);
  const auto lights = prepare_lights(data, n, samples, bins, criterion);
  return errors_at(basis, k, data, n, samples, lights, criterion.percentile);
}

std::vector<BasisError> reconstruction_errors(const Eigen::MatrixXf& basis, const float* coefficients, const float* data,
                                              std::size_t pixels, const BinLayout& bins, const BasisCriterion& criterion) {
  const int n = static_cast<int>(basis.rows());
  const int k = static_cast<int>(basis.cols());
  if (n != bins.size() || k < 1 || k > n) {
    throw InputError("spectral basis", std::to_string(n) + "×" + std::to_string(k) + " basis for " +
                                           std::to_string(bins.size()) + " bins");
  }
  const auto samples = sample_pixels(pixels, criterion.max_samples);
  const auto lights = prepare_lights(data, n, samples, bins, criterion);
  const Eigen::MatrixXd b = basis.cast<double>();
  return errors_of(
      lights, samples.size(), criterion.percentile,
      [&](const Eigen::Matrix<double, 3, Eigen::Dynamic>& w) { return w * b; },
      [&](std::size_t i) { return Eigen::Map<const Eigen::VectorXf>(coefficients + samples[i] * static_cast<std::size_t>(k), k); });
}

BasisChoice choose_basis_size(const SpectralBasis& basis, const float* data, std::size_t pixels,
                              const BinLayout& bins, const BasisCriterion& criterion) {
  const int n = basis.bins();
  const auto samples = sample_pixels(pixels, criterion.max_samples);
  const auto lights = prepare_lights(data, n, samples, bins, criterion);
  BasisChoice choice;
  for (int k = 1; k <= n; ++k) {
    choice.k = k;
    choice.errors = errors_at(basis, k, data, n, samples, lights, criterion.percentile);
    const bool ok = std::all_of(choice.errors.begin(), choice.errors.end(),
                                [&](const BasisError& e) { return e.percentile <= criterion.max_delta_e; });
    if (ok) break;
  }
  return choice;
}

}  // namespace prizma::spectral
