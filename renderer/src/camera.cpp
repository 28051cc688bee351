#include "prizma/render/camera.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <string>

#include "prizma/spectral/error.h"

namespace prizma::render {

CameraModel::CameraModel(const Camera& camera)
    : m_type(camera.type), m_width(camera.width), m_height(camera.height), m_position(camera.position) {
  using spectral::InputError;
  if (camera.width < 1 || camera.height < 1)
    throw InputError("camera", "image size must be at least 1×1, got " + std::to_string(camera.width) + "×" +
                                   std::to_string(camera.height));
  const Eigen::Vector3d view = camera.look_at - camera.position;
  if (!(view.norm() > 1e-12)) throw InputError("camera", "look_at coincides with position");
  m_forward = view.normalized();
  const Eigen::Vector3d right = m_forward.cross(camera.up);
  if (!(right.norm() > 1e-9 * std::max(1.0, camera.up.norm())))
    throw InputError("camera", "up is zero or parallel to the view direction");
  m_right = right.normalized();
  m_up = m_right.cross(m_forward);
  const double aspect = static_cast<double>(m_width) / m_height;
  if (m_type == CameraType::Perspective) {
    if (!(camera.fov_y_deg > 0.0 && camera.fov_y_deg < 180.0))
      throw InputError("camera", "fov_y_deg must be in (0, 180), got " + std::to_string(camera.fov_y_deg));
    m_half_h = std::tan(0.5 * camera.fov_y_deg * std::numbers::pi / 180.0);
  } else {
    if (!(camera.ortho_height > 0.0 && std::isfinite(camera.ortho_height)))
      throw InputError("camera", "ortho_height must be > 0, got " + std::to_string(camera.ortho_height));
    m_half_h = 0.5 * camera.ortho_height;
  }
  m_half_w = m_half_h * aspect;
}

Ray CameraModel::generate(double px, double py) const {
  const double sx = (2.0 * px / m_width - 1.0) * m_half_w;
  const double sy = (1.0 - 2.0 * py / m_height) * m_half_h;
  if (m_type == CameraType::Perspective) {
    return {m_position, (m_forward + sx * m_right + sy * m_up).normalized()};
  }
  return {m_position + sx * m_right + sy * m_up, m_forward};
}

}  // namespace prizma::render
