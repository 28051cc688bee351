#pragma once
// What the parts of the path tracer share (renderer/src/tracer/*.inl, compiled as the one translation
// unit path_tracer.cpp): includes, the tracer's constants and the lanes of its scratch arrays.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "lanes.h"
#include "majorant_sampler.h"
#include "prizma/render/fluorescence.h"
#include "prizma/render/phase.h"
#include "prizma/spectral/error.h"

namespace prizma::render {
namespace {

// Ratio tracking's Russian roulette: below this largest transmittance, stop with probability kRrStop.
constexpr float kTransmittanceRrThreshold = 0.05f;
constexpr float kTransmittanceRrStop = 0.75f;
// Tracking steps (collisions + shadow steps) one path may take. The scene loader bounds the
// extinction so that a crossing takes at most ~2·10^6 steps; a path beyond this bound (albedo 1
// in a very dense medium) is abandoned as NaN, which the render counts and reports, so every path
// ends in bounded time.
constexpr std::int64_t kMaxPathSteps = std::int64_t{1} << 28;
constexpr float kAbandoned = std::numeric_limits<float>::quiet_NaN();
constexpr double kFloatMax = std::numeric_limits<float>::max();

// Lanes known at compile time (1) or not (0 = scratch.lanes).
template <int kLanes>
int lane_count(const PathScratch& s) {
  return kLanes > 0 ? kLanes : s.lanes;
}

// The lanes of a per-lane array, or of row `row` of a [row][lanes] array.
template <int kLanes>
Lanes<kLanes> lanes_of(std::vector<float>& v, int n, std::size_t row = 0) {
  return Lanes<kLanes>(v.data() + row * static_cast<std::size_t>(n), n);
}
template <int kLanes>
ConstLanes<kLanes> lanes_of(const std::vector<float>& v, int n, std::size_t row = 0) {
  return ConstLanes<kLanes>(v.data() + row * static_cast<std::size_t>(n), n);
}

}  // namespace
}  // namespace prizma::render
