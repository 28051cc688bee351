// PathTracer::PathState: a path between its events. Part of path_tracer.cpp's translation unit (see
// there).
#include "../path_tracer_internal.h"

namespace prizma::render {

// The state of a path between its events: its own lanes are values (LaneArray), what it adds light
// to are views of the results.
template <int kLanes>
struct PathTracer::PathState {
  explicit PathState(int lanes) : n(lanes), w(lanes), rho(lanes) {}

  int n;                 // lanes
  LaneArray<kLanes> w;   // throughput per lane
  // Spectral MIS only (hero ≥ 0): the lanes' normalised technique densities ρ (spectral_mis.inl);
  // unused (never written) under spectral tracking.
  LaneArray<kLanes> rho;
  // Where light seen from here on goes: the diagonal results, or after a fluorescent event the in
  // side of the rank-one term (out.fl_*).
  float* env = nullptr;
  float* em = nullptr;
  float* dir_out = nullptr;
  Eigen::Vector3d pos, dir;
  double t_enter = 0.0, t_exit = 0.0;  // the current ray's interval inside the box
  double phase_pdf = 0.0;  // density of dir's last draw from the phase function (0: camera ray)
  int material = 0;        // at the last scattering
  int hero = -1;           // spectral MIS: the lane the path is sampled for; −1 under spectral tracking
  bool isotropic = false;  // the last event was a fluorescent re-emission (phase 1/4π)
  std::int64_t step_limit = 0;  // collisions + shadow steps at which the path is abandoned

  // The lanes whose mixture the phase sampling draws from and the light estimates weigh it with:
  // spectral MIS's densities ρ, else (spectral tracking) the weights w.
  ConstLanes<kLanes> mix() const { return hero >= 0 ? rho.view() : w.view(); }
  Lanes<kLanes> lanes(float* p) const { return Lanes<kLanes>(p, n); }
};

}  // namespace prizma::render
