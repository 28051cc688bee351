#pragma once
// What every benchmark of a run-time dispatched kernel reports (issue 26): each SIMD level's time,
// measured interleaved in one run (every level once per iteration, the first one rotating, so a
// change in the machine's load falls on all of them), and the level the tools dispatch to next to
// the fastest one. Counters, per level L: ms_L (wall time, median over the iterations) and cpu_ms_L
// (CPU time of the process); dispatched_ms, best_ms (the level of least median), dispatched_over_best
// (the median over the iterations of dispatched time ÷ best time in the same iteration: paired, so
// load that changes between iterations cancels), cpu_dispatched_over_best (the same in CPU time,
// against the level of least CPU time), and dispatch_slower = 1 when both are above 1.05
// (bench/simd-table fails on it). Both: on a loaded machine the wall time of a run longer than a
// time slice includes waits for a core (a 6 ms relight measured 16–20 ms at load 16, CPU time
// 5.9 ms), which made the wall ratio of two levels running the same instructions swing by ±25 %;
// on a quiet one a level that is really slower is slower in both.
// Label: "dispatched avx512, best avx2, best by CPU time avx2".
#include <benchmark/benchmark.h>

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <string>
#include <vector>

#include "prizma/spectral/simd_choice.h"

namespace prizma::bench {

// How much slower than the fastest level the dispatched one may be before it is flagged.
constexpr double kDispatchTolerance = 1.05;

// The median of `v` (0 if empty).
inline double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// CPU seconds of the whole process (every thread).
inline double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// Per level, the wall and CPU seconds of each iteration.
class LevelTimes {
 public:
  explicit LevelTimes(std::vector<spectral::SimdLevel> levels)
      : m_levels(std::move(levels)), m_wall(m_levels.size()), m_cpu(m_levels.size()) {}
  const std::vector<spectral::SimdLevel>& levels() const { return m_levels; }
  // The order in which to run the levels in the next iteration: each time starting one later.
  std::vector<std::size_t> next_order() {
    std::vector<std::size_t> order(m_levels.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = (i + m_round) % order.size();
    ++m_round;
    return order;
  }
  void add(std::size_t level_index, double wall_s, double cpu_s) {
    m_wall[level_index].push_back(wall_s);
    m_cpu[level_index].push_back(cpu_s);
  }
  double median(std::size_t level_index) const { return median_of(m_wall[level_index]); }
  std::size_t index_of(spectral::SimdLevel level) const {
    return static_cast<std::size_t>(std::find(m_levels.begin(), m_levels.end(), level) - m_levels.begin());
  }

  // The counters and label above; `dispatched` is the level the tools run at (one of levels()).
  void report(benchmark::State& state, spectral::SimdLevel dispatched) const {
    const std::size_t d = index_of(dispatched);
    const std::size_t best = fastest(m_wall), cpu_best = fastest(m_cpu);
    for (std::size_t i = 0; i < m_levels.size(); ++i) {
      const std::string name(spectral::simd_level_name(m_levels[i]));
      state.counters["ms_" + name] = 1e3 * median(i);
      state.counters["cpu_ms_" + name] = 1e3 * median_of(m_cpu[i]);
    }
    const double over = paired(m_wall, d, best), cpu_over = paired(m_cpu, d, cpu_best);
    state.counters["dispatched_ms"] = 1e3 * median(d);
    state.counters["best_ms"] = 1e3 * median(best);
    state.counters["dispatched_over_best"] = over;
    state.counters["cpu_dispatched_over_best"] = cpu_over;
    state.counters["dispatch_slower"] = over > kDispatchTolerance && cpu_over > kDispatchTolerance ? 1.0 : 0.0;
    state.SetLabel("dispatched " + std::string(spectral::simd_level_name(dispatched)) + ", best " +
                   std::string(spectral::simd_level_name(m_levels[best])) + ", best by CPU time " +
                   std::string(spectral::simd_level_name(m_levels[cpu_best])));
  }

 private:
  static std::size_t fastest(const std::vector<std::vector<double>>& s) {
    std::size_t best = 0;
    for (std::size_t i = 0; i < s.size(); ++i)
      if (median_of(s[i]) < median_of(s[best])) best = i;
    return best;
  }
  // The median over the iterations of s[a] ÷ s[b] in the same iteration.
  static double paired(const std::vector<std::vector<double>>& s, std::size_t a, std::size_t b) {
    std::vector<double> r;
    for (std::size_t k = 0; k < s[a].size() && k < s[b].size(); ++k) r.push_back(s[a][k] / s[b][k]);
    return median_of(r);
  }

  std::vector<spectral::SimdLevel> m_levels;
  std::vector<std::vector<double>> m_wall, m_cpu;
  std::size_t m_round = 0;
};

// The usual benchmark body: each iteration runs `frame` once at every level of `kernel` (forced,
// wall and CPU time), after `before` (e.g. a baseline timed alongside); the manual time is the dispatched
// level's; then report(). `frame` and `before` take no arguments.
template <class Frame, class Before>
void time_levels(benchmark::State& state, LevelTimes& times, spectral::SimdKernel kernel, spectral::SimdLevel dispatched,
                 Frame&& frame, Before&& before) {
  for (auto _ : state) {
    before();
    double dispatched_s = 0.0;
    for (const std::size_t i : times.next_order()) {
      const spectral::ForcedSimdLevel forced(kernel, times.levels()[i]);
      const double c0 = process_cpu_seconds();
      const auto t0 = std::chrono::steady_clock::now();
      frame();
      benchmark::ClobberMemory();
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      times.add(i, s, process_cpu_seconds() - c0);
      if (times.levels()[i] == dispatched) dispatched_s = s;
    }
    state.SetIterationTime(dispatched_s);
  }
  times.report(state, dispatched);
}

}  // namespace prizma::bench
