// The tracer at each SIMD level (simd_level.h) on one core: CPU microseconds per camera path of the
// peer scene (data/scenes/bench_peer.json, 32 bins, no lights but the environment: free flight,
// phase sampling, roulette) and of the chromatic cube (cube_sphere.json: also a key light, so
// next-event estimation and ratio tracking), every level in turn in each round (interleaved, so a
// change in the machine's load falls on all of them), and each level's speed-up over the baseline;
// with bench_levels.h's counters (ms_L: CPU ms of one round at level L, median; the dispatched
// level, default_simd_level(), against the fastest).
//
//   build/bench/bench_simd [--benchmark_filter=Peer]
#include <benchmark/benchmark.h>
#include <time.h>

#include <string>
#include <vector>

#include "bench_common.h"
#include "bench_levels.h"
#include "prizma/render/camera.h"
#include "prizma/render/path_tracer.h"
#include "prizma/render/rng.h"
#include "prizma/render/simd_level.h"

namespace {

namespace pr = prizma::render;

double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// CPU seconds for `count` all-bins paths from random film positions (the same paths every call).
double trace_paths(const pr::Scene& scene, const pr::PathTracer& tracer, pr::PathScratch& s, int count) {
  const pr::CameraModel camera(scene.camera);
  const auto& bins = scene.settings.bins;
  const double t0 = thread_cpu_seconds();
  for (int k = 0; k < count; ++k) {
    pr::Rng rng(scene.settings.seed, static_cast<std::uint64_t>(k), 0);
    const pr::Ray ray = camera.generate(rng.uniform_double() * camera.width(), rng.uniform_double() * camera.height());
    const double u = rng.uniform_double();
    for (int i = 0; i < bins.size(); ++i) s.in.lambda_nm[i] = static_cast<float>(bins.lo_nm(i) + u * bins.width_nm(i));
    tracer.trace(ray, rng, s);
    benchmark::DoNotOptimize(s.out.environment.data());
  }
  return thread_cpu_seconds() - t0;
}

void simd_levels(benchmark::State& state, const std::string& scene_file, int paths_per_round) {
  const pr::Scene scene = pr::load_scene(prizma::bench::source_data_dir() / "scenes" / scene_file);
  const auto& bins = scene.settings.bins;
  pr::PathTracer tracer(scene, bins.min_nm(), bins.max_nm(), scene.settings.use_majorant_grid);
  pr::PathScratch s;
  tracer.prepare(s, bins.size());
  const std::vector<pr::SimdLevel> levels = pr::supported_simd_levels();
  std::vector<double> seconds(levels.size(), 0.0);
  prizma::bench::LevelTimes times(levels);
  for (auto _ : state) {
    for (const std::size_t l : times.next_order()) {
      tracer.set_simd_level(levels[l]);
      const double round_s = trace_paths(scene, tracer, s, paths_per_round);  // CPU time of this thread
      seconds[l] += round_s;
      times.add(l, round_s, round_s);
    }
  }
  times.report(state, pr::default_simd_level());
  const double paths = static_cast<double>(state.iterations()) * paths_per_round;
  for (std::size_t l = 0; l < levels.size(); ++l) {
    const std::string name(pr::simd_level_name(levels[l]));
    state.counters["us_per_path_" + name] = 1e6 * seconds[l] / paths;
    state.counters["speedup_" + name] = seconds[0] / seconds[l];
  }
}

BENCHMARK_CAPTURE(simd_levels, Peer, std::string("bench_peer.json"), 2000)->Unit(benchmark::kMillisecond)->MinTime(1.5);
BENCHMARK_CAPTURE(simd_levels, Cube, std::string("cube_sphere.json"), 500)->Unit(benchmark::kMillisecond)->MinTime(1.5);

}  // namespace

BENCHMARK_MAIN();
