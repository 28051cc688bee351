#pragma once
// sample_majorant: the one majorant walk that free-flight sampling and ratio tracking share
// (pbrt-v4's SampleT_maj is the model). It walks the majorant grid's cells along a ray segment
// and draws tentative collisions in each cell as a Poisson process of rate μ̄ (the cell's
// majorant): t += −ln(u)/μ̄ until the cell's end. The caller decides what a collision does.
// Residual ratio tracking walks the same cells at each cell's residual rate (sample_segments).
#include <Eigen/Core>
#include <cmath>
#include <cstdint>

#include "prizma/render/camera.h"
#include "prizma/render/majorant_grid.h"
#include "prizma/render/rng.h"

namespace prizma::render {

// One tentative collision: distance along the ray, the point, and its cell's majorant μ̄ (> 0)
// and 1/μ̄.
struct TentativeCollision {
  double t;
  Eigen::Vector3d p;
  float mu;
  float inv_mu;
};

// The walk itself: per cell, on_segment(const MajorantTraversal::Segment&, float& mu) → bool sets
// the rate mu of its tentative collisions (≤ 0: none) or, returning false, stops the walk; then
// on_collision(const TentativeCollision&) → bool at each collision in order (false stops the
// walk). A cell of rate ≤ 0 costs one step and no random number; cells counts the cells visited.
// Returns true when the walk reached t_max, false when a callback stopped it.
template <class OnSegment, class OnCollision>
bool sample_segments(const MajorantGrid& grid, const Ray& ray, double t_min, double t_max, Rng& rng,
                     std::int64_t& cells, OnSegment&& on_segment, OnCollision&& on_collision) {
  MajorantTraversal walk(grid, ray, t_min, t_max);
  MajorantTraversal::Segment seg;
  while (walk.next(seg)) {
    ++cells;
    float mu = 0.0f;
    if (!on_segment(seg, mu)) return false;
    if (!(mu > 0.0f)) continue;
    const float inv_mu = 1.0f / mu;
    double t = seg.t0;
    for (;;) {
      t -= std::log(rng.uniform()) * inv_mu;
      if (t >= seg.t1) break;
      if (!on_collision(TentativeCollision{t, ray.origin + t * ray.direction, mu, inv_mu})) return false;
    }
  }
  return true;
}

// Calls on_collision(const TentativeCollision&) → bool at each tentative collision along ray over
// [t_min, t_max] (the ray must meet the grid's box there), in order, at each cell's majorant; false
// from the callback stops the walk. Cells of majorant 0 cost one step and no random number. cells
// counts the cells visited. Returns true when the walk reached t_max, false when the callback
// stopped it.
template <class OnCollision>
bool sample_majorant(const MajorantGrid& grid, const Ray& ray, double t_min, double t_max, Rng& rng,
                     std::int64_t& cells, OnCollision&& on_collision) {
  return sample_segments(
      grid, ray, t_min, t_max, rng, cells,
      [](const MajorantTraversal::Segment& seg, float& mu) {
        mu = seg.majorant;
        return true;
      },
      on_collision);
}

}  // namespace prizma::render
