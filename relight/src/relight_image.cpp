#include "prizma/relight/relight_image.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Core>
#include <string>
#include <vector>

#include "prizma/relight/relight_simd.h"
#include "prizma/spectral/error.h"

namespace prizma::relight {

namespace {

using LayerTerm = detail::SimdLayer;  // weights: 3·n floats row-major; transport: pixel-major, bins contiguous

}  // namespace

void relight_into(const spectral::SpectralImage& image, const RelightMatrix& matrix, float* xyz_out) {
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
  const int width = image.width;
  tbb::parallel_for(tbb::blocked_range<int>(0, image.height), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y) {
      const std::size_t first = static_cast<std::size_t>(y) * static_cast<std::size_t>(width);
      // Highway's run-time dispatch: the widest SIMD this CPU has (relight_simd.cpp).
      detail::relight_row_simd(terms.data(), static_cast<int>(terms.size()), n, first, width, xyz_out + 3 * first);
    }
  });
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
