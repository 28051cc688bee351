#include "prizma/spectral/relight_image.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "prizma/spectral/bispectral.h"
#include "prizma/spectral/relight_simd.h"
#include "prizma/spectral/error.h"

namespace prizma::spectral {

namespace {

using LayerTerm = detail::SimdTerm;  // weights: 3·n floats row-major; values: pixel-major, n contiguous

}  // namespace

ReradiationWeights reradiation_weights(const SpectralImage& image, Observer cmf) {
  ReradiationWeights k;
  k.cmf = cmf;
  if (image.reradiation.empty()) return k;
  k.in_bins = reradiation_in_bins(image);
  const Matrix3Xd c_out = bin_cmf_integrals(cmf, image.bins);
  for (int l = 0; l < static_cast<int>(image.lights.size()); ++l)
    k.per_light.push_back(reradiation_colour_weights(image, l, c_out, k.in_bins));
  return k;
}

namespace {

// The re-radiation as terms of the same row pass: per light that is on, its K (3·|in| values per
// pixel, rows c' = X, Y, Z of Σ_out cmf·M) with the 3×(3·|in|) weights W[c][c'·|in| + j] =
// output[c][c']·ē[in_j], so that W·K = output · K·ē (docs/fluorescence.md).
void add_reradiation_terms(const SpectralImage& image, const RelightMatrix& matrix, const ReradiationWeights& k,
                           std::vector<float>& weights, std::vector<LayerTerm>& terms) {
  const std::size_t ni = k.in_bins.size();
  const int layers = static_cast<int>(image.lights.size());
  if (static_cast<int>(k.per_light.size()) != layers || k.cmf != matrix.options().cmf)
    throw RuntimeError("relight: re-radiation weights do not match the image or the observer");
  const std::size_t nk = 3 * ni;
  weights.assign(static_cast<std::size_t>(layers) * 3 * nk, 0.0f);
  for (int l = 0; l < layers; ++l) {
    const auto& kl = k.per_light[static_cast<std::size_t>(l)];
    if (kl.size() != image.pixel_count() * nk)
      throw RuntimeError("relight: re-radiation weights do not match the image");
    const ReradiationTermWeights wl = reradiation_term_weights(matrix, k, l);
    float* w = weights.data() + static_cast<std::size_t>(l) * 3 * nk;
    bool any = false;
    for (std::size_t j = 0; j < 3 * nk; ++j) {
      w[j] = static_cast<float>(wl.weights[j]);
      any = any || w[j] != 0.0f;
    }
    if (any) terms.push_back({w, kl.data(), static_cast<int>(nk)});
  }
}

}  // namespace

ReradiationTermWeights reradiation_term_weights(const RelightMatrix& matrix, const ReradiationWeights& k, int light) {
  const std::size_t ni = k.in_bins.size();
  ReradiationTermWeights w;
  w.values_per_pixel = static_cast<int>(3 * ni);
  w.weights.assign(3 * 3 * ni, 0.0);
  const Eigen::VectorXd& avg = matrix.light_bin_average(light);
  for (int c = 0; c < 3; ++c)
    for (int c2 = 0; c2 < 3; ++c2)
      for (std::size_t j = 0; j < ni; ++j)
        w.weights[static_cast<std::size_t>(c) * 3 * ni + static_cast<std::size_t>(c2) * ni + j] =
            matrix.output()(c, c2) * avg[k.in_bins[j]];
  return w;
}

std::vector<LightWeights> light_weights(const RelightMatrix& matrix, int layers, int bins, const std::string& what) {
  if (matrix.light_count() != layers || matrix.bin_count() != bins) {
    throw RuntimeError("relight: matrix is " + std::to_string(matrix.light_count()) + " lights × " +
                                 std::to_string(matrix.bin_count()) + " bins, " + what + " has " +
                                 std::to_string(layers) + " × " + std::to_string(bins));
  }
  std::vector<LightWeights> on;
  for (int l = 0; l < layers; ++l) {
    const Matrix3Xd& m = matrix.light(l);
    if (m.isZero(0.0)) continue;
    LightWeights& w = on.emplace_back();
    w.light = l;
    w.weights.resize(3 * static_cast<std::size_t>(bins));
    for (int c = 0; c < 3; ++c)
      for (int i = 0; i < bins; ++i) w.weights[static_cast<std::size_t>(c * bins + i)] = static_cast<float>(m(c, i));
  }
  return on;
}

void relight_into(const SpectralImage& image, const RelightMatrix& matrix, float* xyz_out,
                  const ReradiationWeights* k) {
  const int n = image.bins.size();
  const int layers = static_cast<int>(image.lights.size());
  const std::vector<LightWeights> on = light_weights(matrix, layers, n, "image");
  for (int l = 0; l < layers; ++l) {
    const auto& data = image.lights[static_cast<std::size_t>(l)].data;
    if (data.size() != image.pixel_count() * static_cast<std::size_t>(n)) {
      throw RuntimeError("relight: layer " + image.lights[static_cast<std::size_t>(l)].name +
                                   " has " + std::to_string(data.size()) + " values, expected " +
                                   std::to_string(image.pixel_count() * static_cast<std::size_t>(n)));
    }
  }
  std::vector<LayerTerm> terms;
  for (const LightWeights& w : on)
    terms.push_back({w.weights.data(), image.lights[static_cast<std::size_t>(w.light)].data.data(), n});
  // Bispectral images: the re-radiation joins the same pass (K once per observer: kept by the caller,
  // else computed here for this one relight).
  ReradiationWeights local;
  std::vector<float> rerad_weights;
  if (!image.reradiation.empty()) {
    if (k == nullptr) {
      local = reradiation_weights(image, matrix.options().cmf);
      k = &local;
    }
    add_reradiation_terms(image, matrix, *k, rerad_weights, terms);
  }
  const int width = image.width;
  // The SIMD level chosen for this CPU (relight_simd.h): every level gives the same bits.
  const detail::RelightRowKernel row = detail::relight_row_kernel();
  tbb::parallel_for(tbb::blocked_range<int>(0, image.height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y) {
      const std::size_t first = static_cast<std::size_t>(y) * static_cast<std::size_t>(width);
      row(terms.data(), static_cast<int>(terms.size()), first, width, xyz_out + 3 * first);
    }
  });
}

XyzImage relight_image(const SpectralImage& image, const RelightMatrix& matrix) {
  XyzImage out;
  out.width = image.width;
  out.height = image.height;
  out.xyz.resize(3 * image.pixel_count());
  relight_into(image, matrix, out.xyz.data());
  return out;
}

}  // namespace prizma::spectral
