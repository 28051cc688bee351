// PathTracer's guide data for the denoiser (prizma-render --features; docs/denoise.md, "Guides"):
// where a path first scatters, which no light can change. Part of path_tracer.cpp's translation
// unit (see there). Two stores per path, made for every path; the film reads them only with
// --features, so renders without it are the same bits as before.
#include "../path_tracer_internal.h"

namespace prizma::render {

// At the start of a path: it has not scattered (yet).
inline void begin_guides(PathResult& out) {
  out.scattered = false;
  out.first_scatter_depth = 0.0f;
}

// At a scattering event at `pos`: the first one's distance along the camera ray from where the ray
// enters the volume's bounds (at parameter t_enter: the path's own while no bounce has happened), as
// a fraction of the bounds' diagonal (so in [0, 1]).
inline void record_first_scattering(const Eigen::Vector3d& pos, double t_enter, const Ray& camera_ray,
                                    const Medium& medium, PathResult& out) {
  if (out.scattered) return;
  out.scattered = true;
  const double along = (pos - camera_ray.origin).dot(camera_ray.direction) / camera_ray.direction.squaredNorm();
  const double diagonal = (medium.bounds_max - medium.bounds_min).norm();
  out.first_scatter_depth = static_cast<float>((along - t_enter) * camera_ray.direction.norm() / diagonal);
}

}  // namespace prizma::render
