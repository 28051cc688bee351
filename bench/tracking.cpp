// bench_tracking: throughput of the path tracer's inner loops (Google Benchmark). The machine is shared,
// so every benchmark times its configuration and its baseline interleaved in the same iterations and
// reports the ratio as a counter; absolute rates are for orientation only.
//   Tracking/<medium>          free-flight + ratio-tracking steps per second on one core, with and
//                              without the majorant grid (dense box; mostly empty box)
//   BinCost/<n>                a spectral-tracking path carrying n bins vs a one-wavelength path
//   AllBinsVsSingle            the default 16 bins, chromatic cube: all-bins path vs VPT's single path
//   Threads                    render() on 1 vs 2 threads (speed-up)
//   Interpolation/mri          the MRI scene (data/scenes/mri.json), 16 bins: a path through the
//                              trilinear, post-classified medium vs the same paths with nearest voxels
#include <benchmark/benchmark.h>

#include <chrono>

#include "bench_common.h"
#include "prizma/render/camera.h"
#include "prizma/render/path_tracer.h"
#include "prizma/render/rng.h"

namespace pb = prizma::bench;
namespace pr = prizma::render;
namespace ps = prizma::spectral;

namespace {

using Clock = std::chrono::steady_clock;

// A box of n³ voxels; `fill` decides per voxel centre (in [−1, 1]³) whether it holds the material.
pr::Scene box_scene(int n, bool (*fill)(double, double, double), const pr::Material& mat) {
  pr::Scene scene;
  auto& med = scene.medium;
  med.dims = {n, n, n};
  med.material.assign(med.voxel_count(), pr::Medium::kEmpty);
  med.density.assign(med.voxel_count(), 0.0f);
  med.materials = {mat};
  std::size_t v = 0;
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x, ++v) {
        auto c = [n](int i) { return (i + 0.5) / n * 2.0 - 1.0; };
        if (fill(c(x), c(y), c(z))) {
          med.material[v] = 0;
          med.density[v] = 1.0f;
        }
      }
  pr::Light key;
  key.name = "key";
  key.direction = Eigen::Vector3d(1, 1, 1);
  pr::Light env;
  env.name = "env";
  scene.lights = {key, env};
  scene.camera.width = 64;
  scene.camera.height = 64;
  scene.hash = "bench-box";
  return scene;
}

pr::Material chromatic_material(double sigma_scale) {
  pr::Material m;
  m.name = "chromatic";
  m.albedo = ps::Spectrum({380, 480, 580, 780}, {0.95, 0.9, 0.7, 0.5});
  m.sigma_t_per_unit = ps::Spectrum({380, 500, 600, 780}, {2.0 * sigma_scale, 1.5 * sigma_scale, sigma_scale, 0.8 * sigma_scale});
  m.anisotropy = ps::Spectrum::constant(0.3);
  return m;
}

const pr::Scene& dense_scene() {
  static const pr::Scene s = box_scene(64, [](double, double, double) { return true; }, chromatic_material(10.0));
  return s;
}
// The dense box with the scheme forced to `max` (an absorption event per collision, as a
// one-wavelength path has): where `auto` takes `implicit` (absorption left in the weight, longer
// paths of lower variance), the per-path cost ratio compares paths of different lengths.
const pr::Scene& dense_max_scene() {
  static const pr::Scene s = [] {
    pr::Scene sc = dense_scene();
    sc.settings.event_probabilities = pr::EventProbabilities::Max;
    return sc;
  }();
  return s;
}
// A sphere of radius 0.25 in [−1, 1]³: 0.8 % of the box holds material.
const pr::Scene& sparse_scene() {
  static const pr::Scene s = box_scene(
      128, [](double x, double y, double z) { return x * x + y * y + z * z < 0.0625; }, chromatic_material(40.0));
  return s;
}
const pr::Scene& cube_scene() {
  static const pr::Scene s = [] {
    pr::Scene sc;
    std::string why;
    if (!pb::load_bench_scene("cube", sc, why)) sc = pb::builtin_cube_sphere(128);
    sc.camera.width = 64;
    sc.camera.height = 64;
    return sc;
  }();
  return s;
}

struct BatchResult {
  double seconds = 0.0;
  pr::PathCounters counters;
  std::int64_t paths = 0;
};

// Traces `count` camera paths (random film positions) with `lanes` lanes over `bins`: lanes == bins
// carries every bin (shared jitter, as render() does), lanes == 1 draws one bin (VPT's method).
void trace_batch(const pr::Scene& scene, const pr::PathTracer& tracer, pr::PathScratch& scratch,
                 const ps::BinLayout& bins, std::uint64_t seed, int count, BatchResult& out) {
  const pr::CameraModel camera(scene.camera);
  const int nb = bins.size();
  const auto before = scratch.counters;
  const auto t0 = Clock::now();
  for (int k = 0; k < count; ++k) {
    pr::Rng rng(seed, static_cast<std::uint64_t>(k), 0);
    const pr::Ray ray = camera.generate(rng.uniform_double() * camera.width(), rng.uniform_double() * camera.height());
    const double u = rng.uniform_double();
    if (scratch.lanes == 1) {
      const int b = std::min(nb - 1, static_cast<int>(rng.uniform_double() * nb));
      scratch.in.lambda_nm[0] = static_cast<float>(bins.lo_nm(b) + u * bins.width_nm(b));
    } else {
      for (int i = 0; i < nb; ++i) scratch.in.lambda_nm[i] = static_cast<float>(bins.lo_nm(i) + u * bins.width_nm(i));
    }
    tracer.trace(ray, rng, scratch);
    benchmark::DoNotOptimize(scratch.out.environment.data());
  }
  out.seconds += std::chrono::duration<double>(Clock::now() - t0).count();
  out.paths += count;
  out.counters.collisions += scratch.counters.collisions - before.collisions;
  out.counters.shadow_steps += scratch.counters.shadow_steps - before.shadow_steps;
  out.counters.majorant_cells += scratch.counters.majorant_cells - before.majorant_cells;
  out.counters.paths_in_volume += scratch.counters.paths_in_volume - before.paths_in_volume;
}

// Tracking steps per second on one core, grid vs no grid interleaved; single-lane paths.
void tracking(benchmark::State& state, const pr::Scene& scene) {
  const ps::BinLayout bins;
  const pr::PathTracer with_grid(scene, bins.min_nm(), bins.max_nm(), true);
  const pr::PathTracer no_grid(scene, bins.min_nm(), bins.max_nm(), false);
  pr::PathScratch sa, sb;
  with_grid.prepare(sa, 1);
  no_grid.prepare(sb, 1);
  BatchResult a, b;
  std::uint64_t seed = 1;
  for (auto _ : state) {
    // Alternate which configuration goes first (the second finds the same rays' voxels in cache).
    if (seed % 2) {
      trace_batch(scene, with_grid, sa, bins, seed, 256, a);
      trace_batch(scene, no_grid, sb, bins, seed, 256, b);
    } else {
      trace_batch(scene, no_grid, sb, bins, seed, 256, b);
      trace_batch(scene, with_grid, sa, bins, seed, 256, a);
    }
    ++seed;
  }
  auto steps = [](const BatchResult& r) {
    return static_cast<double>(r.counters.collisions + r.counters.shadow_steps);
  };
  state.counters["grid_Msteps_per_s"] = steps(a) / a.seconds * 1e-6;
  state.counters["nogrid_Msteps_per_s"] = steps(b) / b.seconds * 1e-6;
  state.counters["grid_Mcells_per_s"] = static_cast<double>(a.counters.majorant_cells) / a.seconds * 1e-6;
  state.counters["grid_us_per_path"] = a.seconds / static_cast<double>(a.paths) * 1e6;
  state.counters["nogrid_us_per_path"] = b.seconds / static_cast<double>(b.paths) * 1e6;
  state.counters["grid_steps_per_path"] = steps(a) / static_cast<double>(a.paths);
  state.counters["nogrid_steps_per_path"] = steps(b) / static_cast<double>(b.paths);
  state.counters["path_speedup_grid"] = b.seconds / a.seconds;
}

// Cost of a path carrying n bins relative to a one-wavelength path over the same n-bin layout.
void bin_cost(benchmark::State& state, const pr::Scene& scene, int n) {
  const ps::BinLayout bins = ps::BinLayout::linear(380, 780, n);
  const pr::PathTracer tracer(scene, bins.min_nm(), bins.max_nm(), true);
  pr::PathScratch all, one;
  tracer.prepare(all, n);
  tracer.prepare(one, 1);
  BatchResult a, b;
  std::uint64_t seed = 1;
  const int batch = n >= 64 ? 64 : 256;
  for (auto _ : state) {
    if (seed % 2) {
      trace_batch(scene, tracer, all, bins, seed, batch, a);
      trace_batch(scene, tracer, one, bins, seed, batch, b);
    } else {
      trace_batch(scene, tracer, one, bins, seed, batch, b);
      trace_batch(scene, tracer, all, bins, seed, batch, a);
    }
    ++seed;
  }
  state.counters["bins"] = n;
  state.counters["allbins_us_per_path"] = a.seconds / static_cast<double>(a.paths) * 1e6;
  state.counters["single_us_per_path"] = b.seconds / static_cast<double>(b.paths) * 1e6;
  state.counters["cost_ratio"] = (a.seconds / static_cast<double>(a.paths)) / (b.seconds / static_cast<double>(b.paths));
  state.counters["allbins_collisions_per_path"] =
      static_cast<double>(a.counters.collisions) / static_cast<double>(a.paths);
  state.counters["single_collisions_per_path"] =
      static_cast<double>(b.counters.collisions) / static_cast<double>(b.paths);
  // Ratio tracking toward the lights continues until every lane's transmittance is small, so an
  // all-bins path takes more shadow steps than a one-wavelength path (its reddest, thinnest bins).
  state.counters["allbins_shadow_steps_per_path"] =
      static_cast<double>(a.counters.shadow_steps) / static_cast<double>(a.paths);
  state.counters["single_shadow_steps_per_path"] =
      static_cast<double>(b.counters.shadow_steps) / static_cast<double>(b.paths);
}

// render() on 1 and 2 threads, interleaved: speed-up = t1 / t2.
void threads(benchmark::State& state, const pr::Scene& base) {
  pr::Scene s = base;
  s.camera.width = 96;
  s.camera.height = 96;
  s.settings.sample_begin = 0;
  s.settings.sample_end = 16;
  double t1 = 0, t2 = 0;
  int k = 0;
  for (auto _ : state) {
    pr::RenderStats st;
    for (int order = 0; order < 2; ++order) {
      const int threads = (order + k) % 2 == 0 ? 1 : 2;
      s.settings.threads = threads;
      pr::render(s, {}, &st);
      (threads == 1 ? t1 : t2) += st.wall_seconds;
    }
    ++k;
  }
  state.counters["t1_s"] = t1 / static_cast<double>(state.iterations());
  state.counters["t2_s"] = t2 / static_cast<double>(state.iterations());
  state.counters["speedup_2_threads"] = t1 / t2;
}

// A path through the trilinear medium vs the nearest-voxel medium of the same scene, interleaved.
void interpolation(benchmark::State& state, const std::string& name) {
  pr::Scene tri;
  std::string why;
  if (!pb::load_bench_scene(name, tri, why)) {
    state.SkipWithError(why.c_str());
    return;
  }
  tri.camera.width = 64;
  tri.camera.height = 64;
  pr::Scene near = tri;
  near.medium.interpolation = pr::Interpolation::Nearest;
  const ps::BinLayout& bins = tri.settings.bins;
  const pr::PathTracer ta(tri, bins.min_nm(), bins.max_nm(), true), tb(near, bins.min_nm(), bins.max_nm(), true);
  pr::PathScratch sa, sb;
  ta.prepare(sa, bins.size());
  tb.prepare(sb, bins.size());
  BatchResult a, b;
  std::uint64_t seed = 1;
  for (auto _ : state) {
    if (seed % 2) {
      trace_batch(tri, ta, sa, bins, seed, 256, a);
      trace_batch(near, tb, sb, bins, seed, 256, b);
    } else {
      trace_batch(near, tb, sb, bins, seed, 256, b);
      trace_batch(tri, ta, sa, bins, seed, 256, a);
    }
    ++seed;
  }
  auto per_path = [](const BatchResult& r) { return r.seconds / static_cast<double>(r.paths) * 1e6; };
  auto steps = [](const BatchResult& r) {
    return static_cast<double>(r.counters.collisions + r.counters.shadow_steps) / static_cast<double>(r.paths);
  };
  state.counters["trilinear_us_per_path"] = per_path(a);
  state.counters["nearest_us_per_path"] = per_path(b);
  state.counters["trilinear_steps_per_path"] = steps(a);
  state.counters["nearest_steps_per_path"] = steps(b);
  state.counters["trilinear_ns_per_step"] = a.seconds / (steps(a) * static_cast<double>(a.paths)) * 1e9;
  state.counters["nearest_ns_per_step"] = b.seconds / (steps(b) * static_cast<double>(b.paths)) * 1e9;
  state.counters["cost_ratio"] = per_path(a) / per_path(b);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::RegisterBenchmark("Tracking/dense", [](benchmark::State& s) { tracking(s, dense_scene()); })
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("Tracking/mostly_empty", [](benchmark::State& s) { tracking(s, sparse_scene()); })
      ->Unit(benchmark::kMillisecond);
  for (int n : {1, 4, 16, 64, 256})
    benchmark::RegisterBenchmark(("BinCost/" + std::to_string(n)).c_str(),
                                 [n](benchmark::State& s) { bin_cost(s, cube_scene(), n); })
        ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("AllBinsVsSingle/cube_16bins", [](benchmark::State& s) { bin_cost(s, cube_scene(), 16); })
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("AllBinsVsSingle/dense_16bins", [](benchmark::State& s) { bin_cost(s, dense_scene(), 16); })
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("AllBinsVsSingle/dense_16bins_max", [](benchmark::State& s) { bin_cost(s, dense_max_scene(), 16); })
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("Threads/cube", [](benchmark::State& s) { threads(s, cube_scene()); })
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
  benchmark::RegisterBenchmark("Interpolation/mri", [](benchmark::State& s) { interpolation(s, "mri"); })
      ->Unit(benchmark::kMillisecond);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
