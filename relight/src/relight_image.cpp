#include "prizma/relight/relight_image.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "prizma/spectral/bispectral.h"
#include "prizma/spectral/error.h"

namespace prizma::relight {

namespace {

// One light's matrix in row-major order (3 rows of n weights) and its layer's transport.
struct LayerTerm {
  const float* weights;    // 3·n floats, row-major
  const float* transport;  // width·height·n floats, pixel-major, bins contiguous
};

// XYZ of a row of pixels: for each pixel Σ_l M_l·T_l. N > 0 fixes the bin count at compile time so
// Eigen unrolls the three dot products into SIMD packets; N = 0 is the general case.
template <int N>
void relight_row(const std::vector<LayerTerm>& terms, int n, std::size_t first_pixel, int width, float* out) {
  constexpr int kRows = 3;
  using Weights = Eigen::Matrix<float, kRows, (N > 0 ? N : Eigen::Dynamic), Eigen::RowMajor>;
  using Bins = Eigen::Matrix<float, (N > 0 ? N : Eigen::Dynamic), 1>;
  const std::size_t stride = static_cast<std::size_t>(n);
  for (int x = 0; x < width; ++x) {
    const std::size_t p = first_pixel + static_cast<std::size_t>(x);
    Eigen::Vector3f xyz = Eigen::Vector3f::Zero();
    for (const LayerTerm& term : terms) {
      const Eigen::Map<const Weights> m(term.weights, kRows, n);
      const Eigen::Map<const Bins> t(term.transport + p * stride, n);
      xyz.noalias() += m.lazyProduct(t);
    }
    out[3 * x + 0] = xyz.x();
    out[3 * x + 1] = xyz.y();
    out[3 * x + 2] = xyz.z();
  }
}

using RowKernel = void (*)(const std::vector<LayerTerm>&, int, std::size_t, int, float*);

RowKernel kernel_for(int n) {
  switch (n) {
    case 4: return &relight_row<4>;
    case 8: return &relight_row<8>;
    case 12: return &relight_row<12>;
    case 16: return &relight_row<16>;
    case 24: return &relight_row<24>;
    case 32: return &relight_row<32>;
    case 48: return &relight_row<48>;
    case 64: return &relight_row<64>;
    default: return &relight_row<0>;
  }
}

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

void relight_into(const spectral::SpectralImage& image, const RelightMatrix& matrix, float* xyz_out,
                  const ReradiationWeights* k) {
  const int n = image.bins.size();
  const int layers = static_cast<int>(image.lights.size());
  if (matrix.light_count() != layers || matrix.bin_count() != n) {
    throw spectral::RuntimeError("relight: matrix is " + std::to_string(matrix.light_count()) + " lights × " +
                                 std::to_string(matrix.bin_count()) + " bins, image has " +
                                 std::to_string(layers) + " × " + std::to_string(n));
  }
  // Row-major float weights per light; lights whose matrix is zero ("off") are skipped entirely.
  std::vector<float> weights(static_cast<std::size_t>(layers) * 3 * static_cast<std::size_t>(n));
  std::vector<LayerTerm> terms;
  for (int l = 0; l < layers; ++l) {
    const Matrix3Xd& m = matrix.light(l);
    float* w = weights.data() + static_cast<std::size_t>(l) * 3 * static_cast<std::size_t>(n);
    for (int c = 0; c < 3; ++c)
      for (int i = 0; i < n; ++i) w[c * n + i] = static_cast<float>(m(c, i));
    const auto& data = image.lights[static_cast<std::size_t>(l)].data;
    if (data.size() != image.pixel_count() * static_cast<std::size_t>(n)) {
      throw spectral::RuntimeError("relight: layer " + image.lights[static_cast<std::size_t>(l)].name +
                                   " has " + std::to_string(data.size()) + " values, expected " +
                                   std::to_string(image.pixel_count() * static_cast<std::size_t>(n)));
    }
    if (!m.isZero(0.0)) terms.push_back({w, data.data()});
  }
  const RowKernel kernel = kernel_for(n);
  const int width = image.width;
  tbb::parallel_for(tbb::blocked_range<int>(0, image.height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y) {
      const std::size_t first = static_cast<std::size_t>(y) * static_cast<std::size_t>(width);
      kernel(terms, n, first, width, xyz_out + 3 * first);
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
