#pragma once
// XyzImage: a relit image, interleaved float CIE XYZ (D65-relative, white Y = 1 at exposure 0).
#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace prizma::spectral {

struct XyzImage {
  int width = 0;
  int height = 0;
  // xyz[3·(y·width + x) + c], c = 0, 1, 2 for X, Y, Z.
  std::vector<float> xyz;

  std::size_t pixel_count() const { return static_cast<std::size_t>(width) * height; }
  Eigen::Vector3d at(int x, int y) const {
    const std::size_t i = 3 * (static_cast<std::size_t>(y) * width + x);
    return {xyz[i], xyz[i + 1], xyz[i + 2]};
  }
};

}  // namespace prizma::spectral
