#pragma once
// MaterialRule: how one range of volume values becomes a material with a density (first matching
// rule wins). Applied at voxel centres (nearest interpolation) or to the value interpolated at a
// point (trilinear, post-classification); see transfer_function.h and docs/scene-format.md.
#include <limits>
#include <vector>

namespace prizma::render {

// Piecewise-linear density multiplier over the raw value; constant beyond the end points.
// No points = density 1 everywhere.
struct DensityRamp {
  std::vector<double> values;     // strictly increasing
  std::vector<double> densities;  // ≥ 0, finite, same size as values
  double eval(double value) const;
  // The largest density over values in [lo, hi] (lo ≤ hi): at the ends and the points inside.
  double max_over(double lo, double hi) const;
  // The least density over values in [lo, hi] (lo ≤ hi), likewise.
  double min_over(double lo, double hi) const;
};

// Voxels whose raw value v satisfies value_lo ≤ v ≤ value_hi get `material` (first matching rule).
struct MaterialRule {
  double value_lo = -std::numeric_limits<double>::infinity();
  double value_hi = std::numeric_limits<double>::infinity();
  int material = 0;  // index into TransferFunction::materials
  DensityRamp density;
};

}  // namespace prizma::render
