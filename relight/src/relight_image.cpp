#include "prizma/relight/relight_image.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "prizma/spectral/bispectral.h"
#include "prizma/relight/relight_simd.h"
#include "prizma/spectral/error.h"

namespace prizma::relight {

namespace {

using LayerTerm = detail::SimdLayer;  // weights: 3·n floats row-major; transport: pixel-major, bins contiguous

}  // namespace

ReradiationWeights reradiation_weights(const spectral::SpectralImage& image, spectral::Observer cmf) {
  ReradiationWeights k;
  k.cmf = cmf;
  if (image.reradiation.empty()) return k;
  k.in_bins = spectral::reradiation_in_bins(image);
  const Matrix3Xd c_out = bin_cmf_integrals(cmf, image.bins);
  for (int l = 0; l < static_cast<int>(image.lights.size()); ++l)
    k.per_light.push_back(spectral::reradiation_colour_weights(image, l, c_out, k.in_bins));
  return k;
}

namespace {

// XYZ += output · K·ē per pixel and light: the re-radiated light, a 3×|in| product per pixel.
void add_reradiation(const spectral::SpectralImage& image, const RelightMatrix& matrix, const ReradiationWeights& k,
                     float* xyz_out) {
  const std::size_t ni = k.in_bins.size();
  const int layers = static_cast<int>(image.lights.size());
  if (static_cast<int>(k.per_light.size()) != layers || k.cmf != matrix.options().cmf)
    throw spectral::RuntimeError("relight: re-radiation weights do not match the image or the observer");
  std::vector<float> e(static_cast<std::size_t>(layers) * ni);
  std::vector<int> on;
  for (int l = 0; l < layers; ++l) {
    if (k.per_light[static_cast<std::size_t>(l)].size() != image.pixel_count() * 3 * ni)
      throw spectral::RuntimeError("relight: re-radiation weights do not match the image");
    const Eigen::VectorXd& avg = matrix.light_bin_average(l);
    bool any = false;
    for (std::size_t j = 0; j < ni; ++j) {
      e[static_cast<std::size_t>(l) * ni + j] = static_cast<float>(avg[k.in_bins[j]]);
      any = any || avg[k.in_bins[j]] != 0.0;
    }
    if (any) on.push_back(l);
  }
  if (on.empty()) return;
  const Eigen::Matrix3f out = matrix.output().cast<float>();
  using Weights = Eigen::Matrix<float, 3, Eigen::Dynamic, Eigen::RowMajor>;
  using Bins = Eigen::Matrix<float, Eigen::Dynamic, 1>;
  const auto nk = static_cast<Eigen::Index>(ni);
  // Rows of pixels, as the diagonal kernel: one task per row, Eigen's packets over the in bins.
  tbb::parallel_for(tbb::blocked_range<int>(0, image.height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y) {
      const std::size_t first = static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width);
      for (std::size_t p = first; p != first + static_cast<std::size_t>(image.width); ++p) {
        Eigen::Vector3f v = Eigen::Vector3f::Zero();
        for (int l : on) {
          const Eigen::Map<const Weights> kk(k.per_light[static_cast<std::size_t>(l)].data() + p * 3 * ni, 3, nk);
          const Eigen::Map<const Bins> el(e.data() + static_cast<std::size_t>(l) * ni, nk);
          v.noalias() += kk.lazyProduct(el);
        }
        const Eigen::Vector3f add = out * v;
        for (int c = 0; c < 3; ++c) xyz_out[3 * p + static_cast<std::size_t>(c)] += add[c];
      }
    }
  });
}

}  // namespace

std::vector<LightWeights> light_weights(const RelightMatrix& matrix, int layers, int bins, const std::string& what) {
  if (matrix.light_count() != layers || matrix.bin_count() != bins) {
    throw spectral::RuntimeError("relight: matrix is " + std::to_string(matrix.light_count()) + " lights × " +
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

void relight_into(const spectral::SpectralImage& image, const RelightMatrix& matrix, float* xyz_out,
                  const ReradiationWeights* k) {
  const int n = image.bins.size();
  const int layers = static_cast<int>(image.lights.size());
  const std::vector<LightWeights> on = light_weights(matrix, layers, n, "image");
  for (int l = 0; l < layers; ++l) {
    const auto& data = image.lights[static_cast<std::size_t>(l)].data;
    if (data.size() != image.pixel_count() * static_cast<std::size_t>(n)) {
      throw spectral::RuntimeError("relight: layer " + image.lights[static_cast<std::size_t>(l)].name +
                                   " has " + std::to_string(data.size()) + " values, expected " +
                                   std::to_string(image.pixel_count() * static_cast<std::size_t>(n)));
    }
  }
  std::vector<LayerTerm> terms;
  for (const LightWeights& w : on) terms.push_back({w.weights.data(), image.lights[static_cast<std::size_t>(w.light)].data.data()});
  const int width = image.width;
  tbb::parallel_for(tbb::blocked_range<int>(0, image.height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y) {
      const std::size_t first = static_cast<std::size_t>(y) * static_cast<std::size_t>(width);
      // Highway's run-time dispatch: the widest SIMD this CPU has (relight_simd.cpp).
      detail::relight_row_simd(terms.data(), static_cast<int>(terms.size()), n, first, width, xyz_out + 3 * first);
    }
  });
  if (!image.reradiation.empty()) {
    if (k != nullptr) {
      add_reradiation(image, matrix, *k, xyz_out);
    } else {
      const ReradiationWeights local = reradiation_weights(image, matrix.options().cmf);
      add_reradiation(image, matrix, local, xyz_out);
    }
  }
}

XyzImage relight_image(const spectral::SpectralImage& image, const RelightMatrix& matrix) {
  XyzImage out;
  out.width = image.width;
  out.height = image.height;
  out.xyz.resize(3 * image.pixel_count());
  relight_into(image, matrix, out.xyz.data());
  return out;
}

}  // namespace prizma::relight
