// PathTracer::PathState: a path between its events. Part of path_tracer.cpp's translation unit (see
// there).
#include "../path_tracer_internal.h"

namespace prizma::render {

// The state of a path between its events.
template <int kLanes>
struct PathTracer::PathState {
  int n;             // lanes
  Lanes<kLanes> w;   // throughput per lane
  // The lanes whose mixture the phase sampling draws from: w (spectral tracking, the same memory),
  // or spectral MIS's normalised technique densities ρ (spectral_mis.inl).
  Lanes<kLanes> mix;
  // Where light seen from here on goes: the diagonal results, or after a fluorescent event the in
  // side of the rank-one term (out.fl_*).
  float* env;
  float* em;
  float* dir_out;
  Eigen::Vector3d pos, dir;
  double t_enter = 0.0, t_exit = 0.0;  // the current ray's interval inside the box
  double phase_pdf = 0.0;  // density of dir's last draw from the phase function (0: camera ray)
  int material = 0;        // at the last scattering
  int hero = -1;           // spectral MIS: the lane the path is sampled for
  bool isotropic = false;  // the last event was a fluorescent re-emission (phase 1/4π)
  std::int64_t step_limit = 0;  // collisions + shadow steps at which the path is abandoned

  Lanes<kLanes> lanes(float* p) const { return Lanes<kLanes>(p, n); }
};

}  // namespace prizma::render
