#pragma once
// What every benchmark of a run-time dispatched kernel reports (issue 26): each SIMD level's time,
// measured interleaved in one run (every level once per iteration, so a change in the machine's
// load falls on all of them), and the level the tools dispatch to next to the fastest one.
// Counters, per level L: ms_L (median over the iterations); dispatched_ms, best_ms,
// dispatched_over_best, and dispatch_slower = 1 when the dispatched level is more than 5 % slower
// than the best (bench/simd-table fails on it). Label: "dispatched avx512, best avx2".
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

#include "prizma/spectral/simd_choice.h"

namespace prizma::bench {

// How much slower than the fastest level the dispatched one may be before it is flagged.
constexpr double kDispatchTolerance = 1.05;

// Per level, the seconds of each iteration.
class LevelTimes {
 public:
  explicit LevelTimes(std::vector<spectral::SimdLevel> levels) : m_levels(std::move(levels)), m_seconds(m_levels.size()) {}
  const std::vector<spectral::SimdLevel>& levels() const { return m_levels; }
  void add(std::size_t level_index, double seconds) { m_seconds[level_index].push_back(seconds); }
  // Median seconds of a level (0 before any iteration).
  double median(std::size_t level_index) const {
    std::vector<double> v = m_seconds[level_index];
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  }
  std::size_t index_of(spectral::SimdLevel level) const {
    return static_cast<std::size_t>(std::find(m_levels.begin(), m_levels.end(), level) - m_levels.begin());
  }

  // The counters and label above; `dispatched` is the level the tools run at (one of levels()).
  void report(benchmark::State& state, spectral::SimdLevel dispatched, const std::string& label_prefix = "") const {
    std::size_t best = 0;
    for (std::size_t i = 0; i < m_levels.size(); ++i) {
      state.counters["ms_" + std::string(spectral::simd_level_name(m_levels[i]))] = 1e3 * median(i);
      if (median(i) < median(best)) best = i;
    }
    const std::size_t d = index_of(dispatched);
    const double over = median(d) / median(best);
    state.counters["dispatched_ms"] = 1e3 * median(d);
    state.counters["best_ms"] = 1e3 * median(best);
    state.counters["dispatched_over_best"] = over;
    state.counters["dispatch_slower"] = over > kDispatchTolerance ? 1.0 : 0.0;
    state.SetLabel(label_prefix + "dispatched " + std::string(spectral::simd_level_name(dispatched)) + ", best " +
                   std::string(spectral::simd_level_name(m_levels[best])));
  }

 private:
  std::vector<spectral::SimdLevel> m_levels;
  std::vector<std::vector<double>> m_seconds;
};

}  // namespace prizma::bench
