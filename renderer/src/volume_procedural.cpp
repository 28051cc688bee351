// Procedural test volumes on a grid over [−1, 1]³ (voxel centres), after VPT's test volumes.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "prizma/render/volume.h"
#include "prizma/spectral/error.h"
#include "volume_budget.h"

namespace prizma::render {

using spectral::InputError;

namespace {

constexpr int kMinResolution = 2;
constexpr int kMaxResolution = 2048;

// cube_sphere (VPT sphere_in_cube): 0 outside, 100 in the cube max|x| < 0.8, 255 in the sphere r < 0.5.
float cube_sphere(double x, double y, double z) {
  if (x * x + y * y + z * z < 0.25) return 255.0f;
  if (std::max({std::abs(x), std::abs(y), std::abs(z)}) < 0.8) return 100.0f;
  return 0.0f;
}

// metamer_pair: spheres of radius 0.4 centred at x = −0.5 (value 100) and x = +0.5 (value 200); the
// gap between them is 0.2 wide.
float metamer_pair(double x, double y, double z) {
  const double r2 = 0.4 * 0.4;
  const double yz2 = y * y + z * z;
  if ((x + 0.5) * (x + 0.5) + yz2 < r2) return 100.0f;
  if ((x - 0.5) * (x - 0.5) + yz2 < r2) return 200.0f;
  return 0.0f;
}

}  // namespace

std::vector<std::string> procedural_volume_names() { return {"cube_sphere", "homogeneous_box", "metamer_pair"}; }

Volume make_procedural_volume(const std::string& name, int resolution) {
  const std::string input = "procedural volume \"" + name + "\"";
  float (*field)(double, double, double) = nullptr;
  if (name == "cube_sphere") {
    field = cube_sphere;
  } else if (name == "metamer_pair") {
    field = metamer_pair;
  } else if (name != "homogeneous_box") {
    std::string known;
    for (const auto& n : procedural_volume_names()) known += (known.empty() ? "" : ", ") + n;
    throw InputError(input, "unknown procedural volume (known: " + known + ")");
  }
  if (resolution < kMinResolution || resolution > kMaxResolution) {
    throw InputError(input, "resolution must be in [" + std::to_string(kMinResolution) + ", " +
                                std::to_string(kMaxResolution) + "] (got " + std::to_string(resolution) + ")");
  }
  const int n = resolution;
  const std::size_t count = detail::check_volume_fits({n, n, n}, 0, input);

  Volume vol;
  vol.dims = {n, n, n};
  vol.source = name;
  vol.values.assign(count, 1.0f);
  if (field == nullptr) return vol;
  // Voxel centres: coordinate (i + 0.5)/n · 2 − 1.
  // Slices in parallel: each voxel is a pure function of its centre, written by one task.
  auto coord = [n](int i) { return (i + 0.5) / n * 2.0 - 1.0; };
  tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const tbb::blocked_range<int>& zs) {
    for (int z = zs.begin(); z != zs.end(); ++z) {
      std::size_t idx = static_cast<std::size_t>(z) * n * n;
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) vol.values[idx++] = field(coord(x), coord(y), coord(z));
    }
  });
  return vol;
}

}  // namespace prizma::render
