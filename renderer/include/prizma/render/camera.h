#pragma once
// CameraModel: turns a scene Camera into primary rays. Pixel (x, y) has y = 0 at the top row; a
// sample at film position (x + u, y + v), u, v in (0, 1), is a box filter with jittered positions.
#include <Eigen/Core>

#include "prizma/render/scene.h"

namespace prizma::render {

struct Ray {
  Eigen::Vector3d origin;
  Eigen::Vector3d direction;  // unit length
};

class CameraModel {
 public:
  // Throws InputError (input "camera") for a degenerate frame (look_at at the position, up parallel
  // to the view direction), a size < 1, or a field of view / height outside (0, 180) / > 0.
  explicit CameraModel(const Camera& camera);

  int width() const { return m_width; }
  int height() const { return m_height; }
  // The ray through film position (px, py) in pixels (0..width, 0..height, y down).
  Ray generate(double px, double py) const;

 private:
  CameraType m_type;
  int m_width, m_height;
  Eigen::Vector3d m_position, m_forward, m_right, m_up;
  double m_half_h = 1.0;  // half the film height at distance 1 (perspective) or in world units (ortho)
  double m_half_w = 1.0;
};

}  // namespace prizma::render
