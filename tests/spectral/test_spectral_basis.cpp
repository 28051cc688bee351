// Spectral basis of a transport layer: exact at k = n, rank-r images need exactly k = r, and the
// ΔE00 criterion chooses a k that only grows as the bound tightens.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "prizma/spectral/error.h"
#include "prizma/spectral/spectral_basis.h"

namespace prizma::spectral {
namespace {

constexpr int kBins = 16;

BinLayout layout() { return BinLayout::linear(400.0, 700.0, kBins); }

double gauss(double x, double mu, double sigma) { return std::exp(-0.5 * (x - mu) * (x - mu) / (sigma * sigma)); }

// `pixels` spectra, each a random positive mix of `rank` smooth, clearly different spectra, plus
// uniform noise of amplitude `noise`.
std::vector<float> mixture_image(std::size_t pixels, int rank, double noise, unsigned seed) {
  const BinLayout bins = layout();
  std::vector<std::vector<double>> shapes;
  for (int j = 0; j < rank; ++j) {
    std::vector<double> s(kBins);
    const double mu = 420.0 + 260.0 * (rank == 1 ? 0.5 : static_cast<double>(j) / (rank - 1));
    for (int i = 0; i < kBins; ++i) s[static_cast<std::size_t>(i)] = 0.02 + gauss(bins.centre_nm(i), mu, 30.0);
    shapes.push_back(s);
  }
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<float> data(pixels * kBins);
  for (std::size_t p = 0; p < pixels; ++p) {
    std::vector<double> a(static_cast<std::size_t>(rank));
    for (double& v : a) v = u(rng);
    for (int i = 0; i < kBins; ++i) {
      double t = 0.0;
      for (int j = 0; j < rank; ++j) t += a[static_cast<std::size_t>(j)] * shapes[static_cast<std::size_t>(j)][static_cast<std::size_t>(i)];
      t += noise * (u(rng) - 0.5);
      data[p * kBins + static_cast<std::size_t>(i)] = static_cast<float>(std::max(0.0, t));
    }
  }
  return data;
}

TEST(SpectralBasis, GramIsTheSumOfOuterProductsAcrossBlocks) {
  const std::size_t pixels = 5000;  // more than one 4096-pixel block
  const auto data = mixture_image(pixels, 4, 0.05, 1);
  const Eigen::MatrixXd gram = spectral_gram(data.data(), pixels, kBins);
  Eigen::MatrixXd naive = Eigen::MatrixXd::Zero(kBins, kBins);
  for (std::size_t p = 0; p < pixels; ++p)
    for (int i = 0; i < kBins; ++i)
      for (int j = 0; j < kBins; ++j) naive(i, j) += double(data[p * kBins + i]) * double(data[p * kBins + j]);
  EXPECT_LT((gram - naive).cwiseAbs().maxCoeff(), 1e-9 * naive.cwiseAbs().maxCoeff());
}

TEST(SpectralBasis, ExactReconstructionWhenKIsN) {
  const std::size_t pixels = 3000;
  const auto data = mixture_image(pixels, kBins, 0.2, 2);
  const SpectralBasis basis = spectral_basis(data.data(), pixels, kBins);
  ASSERT_EQ(basis.bins(), kBins);
  EXPECT_LT((basis.vectors.transpose() * basis.vectors - Eigen::MatrixXd::Identity(kBins, kBins)).cwiseAbs().maxCoeff(), 1e-12);
  for (int j = 1; j < kBins; ++j) EXPECT_LE(basis.singular_values[j], basis.singular_values[j - 1]);
  const auto coeffs = project_coefficients(basis, kBins, data.data(), pixels);
  const Eigen::MatrixXf b = basis_columns(basis, kBins);
  double worst = 0.0;
  for (std::size_t p = 0; p < pixels; ++p) {
    const Eigen::VectorXf back = b * Eigen::Map<const Eigen::VectorXf>(coeffs.data() + p * kBins, kBins);
    for (int i = 0; i < kBins; ++i) worst = std::max(worst, double(std::abs(back[i] - data[p * kBins + static_cast<std::size_t>(i)])));
  }
  EXPECT_LT(worst, 1e-5);
  for (const BasisError& e : basis_errors(basis, kBins, data.data(), pixels, layout())) {
    EXPECT_LT(e.max, 1e-3) << e.light;
  }
}

TEST(SpectralBasis, RankRImageNeedsExactlyR) {
  const std::size_t pixels = 4000;
  for (int rank : {1, 2, 3, 5}) {
    const auto data = mixture_image(pixels, rank, 0.0, 3);
    const SpectralBasis basis = spectral_basis(data.data(), pixels, kBins);
    EXPECT_LT(basis.singular_values[rank], 1e-5 * basis.singular_values[0]) << "rank " << rank;
    const BasisChoice choice = choose_basis_size(basis, data.data(), pixels, layout());
    EXPECT_EQ(choice.k, rank);
    for (const BasisError& e : choice.errors) EXPECT_LT(e.max, 0.01) << "rank " << rank << " " << e.light;
    if (rank > 1) {
      // One term fewer fails the bound under some test light.
      double worst = 0.0;
      for (const BasisError& e : basis_errors(basis, rank - 1, data.data(), pixels, layout())) worst = std::max(worst, e.percentile);
      EXPECT_GT(worst, 0.5) << "rank " << rank;
    }
  }
}

TEST(SpectralBasis, CriterionIsMonotoneAndMinimal) {
  const std::size_t pixels = 1500;
  const auto data = mixture_image(pixels, 6, 0.01, 4);
  const SpectralBasis basis = spectral_basis(data.data(), pixels, kBins);
  int previous = 0;
  for (double bound : {4.0, 2.0, 1.0, 0.5, 0.25, 0.1, 0.05}) {
    BasisCriterion c;
    c.max_delta_e = bound;
    const BasisChoice choice = choose_basis_size(basis, data.data(), pixels, layout(), c);
    EXPECT_GE(choice.k, previous) << "bound " << bound;
    previous = choice.k;
    ASSERT_EQ(choice.errors.size(), c.lights.size());
    for (const BasisError& e : choice.errors) {
      EXPECT_LE(e.percentile, bound) << "bound " << bound << " " << e.light;
      EXPECT_LE(e.percentile, e.max);
    }
    if (choice.k > 1) {
      double worst = 0.0;
      for (const BasisError& e : basis_errors(basis, choice.k - 1, data.data(), pixels, layout(), c))
        worst = std::max(worst, e.percentile);
      EXPECT_GT(worst, bound) << "k is not the smallest for bound " << bound;
    }
  }
  EXPECT_GT(previous, 1);
}

TEST(SpectralBasis, SamplingIsDeterministicAndBoundsThePixelsEvaluated) {
  const std::size_t pixels = 4000;
  const auto data = mixture_image(pixels, 6, 0.01, 5);
  const SpectralBasis basis = spectral_basis(data.data(), pixels, kBins);
  BasisCriterion c;
  c.max_samples = 500;
  const auto a = basis_errors(basis, 3, data.data(), pixels, layout(), c);
  const auto b = basis_errors(basis, 3, data.data(), pixels, layout(), c);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].percentile, b[i].percentile);
}

TEST(SpectralBasis, RefusesBadShapes) {
  const std::vector<float> data(16, 1.0f);
  EXPECT_THROW(spectral_basis(data.data(), 0, kBins), InputError);
  EXPECT_THROW(spectral_basis(data.data(), 1, 0), InputError);
  const SpectralBasis basis = spectral_basis(data.data(), 1, kBins);
  EXPECT_THROW(project_coefficients(basis, 0, data.data(), 1), InputError);
  EXPECT_THROW(project_coefficients(basis, kBins + 1, data.data(), 1), InputError);
  EXPECT_THROW(basis_errors(basis, 1, data.data(), 1, BinLayout::linear(400.0, 700.0, 8)), InputError);
}

// reconstruction_errors of the projected coefficients are basis_errors (the same statistics of the
// same reconstruction, within rounding), and a perturbed reconstruction is measured as such.
TEST(SpectralBasis, ReconstructionErrorsOfTheProjectionAreTheBasisErrors) {
  const std::size_t pixels = 1200;
  const auto data = mixture_image(pixels, 5, 0.01, 9);
  const SpectralBasis basis = spectral_basis(data.data(), pixels, kBins);
  for (const int k : {2, 4}) {
    std::vector<float> c = project_coefficients(basis, k, data.data(), pixels);
    const auto expected = basis_errors(basis, k, data.data(), pixels, layout());
    const auto got = reconstruction_errors(basis_columns(basis, k), c.data(), data.data(), pixels, layout());
    ASSERT_EQ(got.size(), expected.size());
    for (std::size_t i = 0; i < got.size(); ++i) {
      EXPECT_EQ(got[i].light, expected[i].light);
      EXPECT_NEAR(got[i].percentile, expected[i].percentile, 1e-3 * expected[i].percentile + 1e-6) << got[i].light;
      EXPECT_NEAR(got[i].max, expected[i].max, 1e-3 * expected[i].max + 1e-6) << got[i].light;
    }
  }
  // Exact at k = n; 10 % too bright everywhere is not.
  std::vector<float> c = project_coefficients(basis, kBins, data.data(), pixels);
  for (const BasisError& e : reconstruction_errors(basis_columns(basis, kBins), c.data(), data.data(), pixels, layout()))
    EXPECT_LT(e.max, 0.01) << e.light;
  for (float& v : c) v *= 1.1f;
  for (const BasisError& e : reconstruction_errors(basis_columns(basis, kBins), c.data(), data.data(), pixels, layout()))
    EXPECT_GT(e.percentile, 1.0) << e.light;
  EXPECT_THROW(reconstruction_errors(Eigen::MatrixXf::Zero(kBins + 1, 2), data.data(), data.data(), pixels, layout()),
               InputError);
}

}  // namespace
}  // namespace prizma::spectral
