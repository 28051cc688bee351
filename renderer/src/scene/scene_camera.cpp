// The scene's camera (docs/scene-format.md, "Camera"): perspective or orthographic, where it stands
// and looks, its field of view and the image size.
#include <Eigen/Geometry>  // cross()
#include <cmath>

#include "scene_reader.h"

namespace prizma::render::scene_file {

Camera read_camera(const Reader& rd, const json& j) {
  const std::string path = "camera";
  rd.expect_object(j, path, {"type", "position", "look_at", "up", "fov_deg", "ortho_height", "width", "height"});
  Camera c;
  if (j.contains("type")) {
    const std::string tp = Reader::join(path, "type");
    const std::string t = rd.string(j.at("type"), tp);
    if (t == "perspective") c.type = CameraType::Perspective;
    else if (t == "orthographic") c.type = CameraType::Orthographic;
    else rd.fail(tp, "must be \"perspective\" or \"orthographic\" (got \"" + t + "\")");
  }
  // Coordinates beyond 1e12 scene units leave the ray no precision to resolve a volume (and their
  // squares overflow past 1e154): refused rather than rendered as an empty picture.
  constexpr double kMaxCoordinate = 1e12;
  auto vec = [&](const char* key, Eigen::Vector3d& out) {
    if (!j.contains(key)) return;
    const std::string kp = Reader::join(path, key);
    const auto v = rd.vec3(j.at(key), kp);
    for (int i = 0; i < 3; ++i) {
      if (!(std::abs(v[i]) <= kMaxCoordinate)) {
        rd.fail(Reader::index(kp, i), "must be within ±1e12 (got " + num(v[i]) + ")");
      }
    }
    out = Eigen::Vector3d(v[0], v[1], v[2]);
  };
  vec("position", c.position);
  vec("look_at", c.look_at);
  vec("up", c.up);
  const Eigen::Vector3d forward = c.look_at - c.position;
  if (!(forward.norm() > 1e-9)) rd.fail(Reader::join(path, "look_at"), "must differ from position");
  const auto up = unit_direction(c.up);
  if (!up) rd.fail(Reader::join(path, "up"), "must not be the zero vector");
  c.up = *up;
  if (!(forward.normalized().cross(c.up).norm() > 1e-6)) {
    rd.fail(Reader::join(path, "up"), "must not be parallel to the view direction");
  }
  if (j.contains("fov_deg")) {
    const std::string fp = Reader::join(path, "fov_deg");
    c.fov_y_deg = rd.number(j.at("fov_deg"), fp);
    if (!(c.fov_y_deg > 0.0 && c.fov_y_deg < 180.0)) rd.fail(fp, "must be in (0, 180) (got " + num(c.fov_y_deg) + ")");
  }
  if (j.contains("ortho_height")) c.ortho_height = rd.positive(j.at("ortho_height"), Reader::join(path, "ortho_height"));
  if (j.contains("width")) c.width = static_cast<int>(rd.integer(j.at("width"), Reader::join(path, "width"), 1, kMaxImageSide));
  if (j.contains("height")) c.height = static_cast<int>(rd.integer(j.at("height"), Reader::join(path, "height"), 1, kMaxImageSide));
  return c;
}

}  // namespace prizma::render::scene_file
