#pragma once
// Compressed transport (docs/relight.md, "Compressed transport"): per light layer an orthonormal
// spectral basis from the SVD of the layer's pixel spectra, computed as the eigendecomposition of
// the n×n Gram matrix Σ_p t_p t_pᵀ (memory O(n²), one pass over the pixels), and k coefficients per
// pixel, c_p = B_kᵀ t_p. Relighting from coefficients: XYZ = (M·B_k)·c_p, a 3×k matrix per light.
// k is the smallest for which the relit layer differs from the exact relight by at most a CIEDE2000
// bound at a percentile over pixels, under every one of a set of test lights.
#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "prizma/spectral/bin_layout.h"
#include "prizma/spectral/colour_matching.h"
#include "prizma/spectral/light_spectrum.h"
#include "prizma/spectral/spectral_exr.h"

namespace prizma::spectral {

// Gram matrix G = Σ_p t_p t_pᵀ of `pixels` spectra of n bins (pixel-major, bins contiguous), in
// double, accumulated in fixed blocks in pixel order (deterministic).
Eigen::MatrixXd spectral_gram(const float* data, std::size_t pixels, int n);

struct SpectralBasis {
  // n×n orthonormal, columns sorted by decreasing singular value; each column's largest-magnitude
  // entry is positive (so the basis does not depend on the eigensolver's sign choice).
  Eigen::MatrixXd vectors;
  Eigen::VectorXd singular_values;  // n, decreasing, ≥ 0 (square roots of G's eigenvalues)
  int bins() const { return static_cast<int>(vectors.rows()); }
};

// The basis of one layer (throws InputError for n < 1 or no pixels).
SpectralBasis spectral_basis(const float* data, std::size_t pixels, int n);

// c_p = B_kᵀ t_p for every pixel: `pixels`·k floats, pixel-major (k ≤ n).
std::vector<float> project_coefficients(const SpectralBasis& basis, int k, const float* data, std::size_t pixels);

// The first k basis vectors as an n×k float matrix (what a compressed file stores).
Eigen::MatrixXf basis_columns(const SpectralBasis& basis, int k);

// How k is chosen.
struct BasisCriterion {
  double max_delta_e = 0.5;  // CIEDE2000 bound …
  double percentile = 99.0;  // … at this percentile over pixels
  // Test lights (parse_light_spectrum specs); each is applied to the layer alone, white Y = 1.
  std::vector<std::string> lights = {"D65", "A", "F11", "gaussian:450:20"};
  Observer cmf = Observer::Cie1931_2deg;
  // At most this many pixels (evenly strided, deterministic) are evaluated; 0 = all.
  std::size_t max_samples = std::size_t{1} << 18;
};

// The error of a k-term reconstruction of one layer under one light (BasisError, spectral_exr.h):
// ΔE00 between the relit exact and relit reconstructed spectra, CIELAB relative to the light's white
// (XYZ of T = 1, Y = 1), at criterion.percentile and the maximum.

// The same statistics for a reconstruction as stored, t̂_p = basis·c_p: `basis` n×k (any columns),
// `coefficients` pixels·k floats, pixel-major (e.g. the half values a file holds, as floats).
std::vector<BasisError> reconstruction_errors(const Eigen::MatrixXf& basis, const float* coefficients, const float* data,
                                              std::size_t pixels, const BinLayout& bins,
                                              const BasisCriterion& criterion = {});

struct BasisChoice {
  int k = 0;
  std::vector<BasisError> errors;  // per test light, at the chosen k
};

// ΔE00 statistics of the k-term reconstruction under each of the criterion's lights.
std::vector<BasisError> basis_errors(const SpectralBasis& basis, int k, const float* data, std::size_t pixels,
                                     const BinLayout& bins, const BasisCriterion& criterion = {});

// The smallest k in 1..n whose errors are all ≤ criterion.max_delta_e at criterion.percentile
// (n when none smaller is; k = n reconstructs exactly up to rounding). Scans k upward, so a looser
// bound never gives a larger k.
BasisChoice choose_basis_size(const SpectralBasis& basis, const float* data, std::size_t pixels,
                              const BinLayout& bins, const BasisCriterion& criterion = {});

}  // namespace prizma::spectral
