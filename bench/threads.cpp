// Issue 14 goal 5, thread scaling: where a render's time goes and how much of it is serial.
// Runs a scene through the same steps as prizma-render (load_scene, render, write_spectral_exr) in
// this process and times each phase:
//   load      scene file, volume read, classification into the medium, scene hash
//   setup     PathTracer construction: material bounds, majorant grid, light samplers
//   loop      render()'s passes (the parallel loop over pixels; accumulators included)
//   assemble  render()'s result: per-pixel means and variances into the image
//   write     the spectral EXR (PIZ encode, checksum, preview channels; fsync excluded from CPU)
// First with one thread, by CPU time (CLOCK_PROCESS_CPUTIME_ID: a loaded machine does not inflate
// it), giving each phase's share of the work; then the whole pipeline on 1 and 2 threads,
// interleaved, by wall time: the speed-up, which a loaded machine does inflate (the load is printed).
//
//   bench_threads [--scene FILE] [-D key=value]... [--spp N] [--repeats 3] [--out DIR]
// Driven by bench/threads (writes docs/results/threads.txt).
#include <tbb/global_control.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "bench_common.h"
#include "prizma/render/path_tracer.h"

namespace {

using namespace prizma;
namespace fs = std::filesystem;

double cpu_now() {
  timespec ts{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
double wall_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct Clock {
  bool cpu;
  double now() const { return cpu ? cpu_now() : wall_now(); }
};

constexpr int kPhases = 5;
const char* const kPhaseNames[kPhases] = {"load", "setup", "loop", "assemble", "write"};

struct Phases {
  double t[kPhases] = {0, 0, 0, 0, 0};
  double total() const {
    double s = 0;
    for (double v : t) s += v;
    return s;
  }
};

struct Config {
  fs::path scene;
  std::vector<render::SceneOverride> overrides;
  std::int64_t spp = 0;
  fs::path out_dir;
};

// One pipeline run on `threads` threads, timed by `clock`.
Phases run_once(const Config& cfg, int threads, const Clock& clock, std::string* checksum = nullptr) {
  const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
  Phases p;
  double t0 = clock.now();
  render::Scene scene = render::load_scene(cfg.scene, cfg.overrides);
  if (cfg.spp > 0) scene.settings.sample_end = scene.settings.sample_begin + cfg.spp;
  scene.settings.threads = threads;
  double t1 = clock.now();
  p.t[0] = t1 - t0;
  {  // the set-up render() does first, timed on its own (render() repeats it: subtracted below)
    const spectral::BinLayout& bins = scene.settings.bins;
    const render::PathTracer tracer(scene, bins.min_nm(), bins.max_nm(), scene.settings.use_majorant_grid);
  }
  double t2 = clock.now();
  p.t[1] = t2 - t1;
  double loop_end = 0;
  render::RenderCallbacks cb;
  cb.samples_per_pass = scene.settings.sample_end - scene.settings.sample_begin;  // one pass
  cb.progress = [&](const render::RenderProgress&) { loop_end = clock.now(); };
  render::RenderStats stats;
  const spectral::SpectralImage image = render::render(scene, cb, &stats);
  double t3 = clock.now();
  p.t[2] = std::max(0.0, loop_end - t2 - p.t[1]);
  p.t[3] = t3 - loop_end;
  spectral::ExrWriteOptions wo;
  wo.threads = threads;
  spectral::write_spectral_exr(cfg.out_dir / ("bench_threads_" + std::to_string(threads) + ".exr"), image, wo);
  p.t[4] = clock.now() - t3;
  if (checksum) *checksum = spectral::spectral_pixel_checksum(image);
  return p;
}

std::string fmt(double v, int prec) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", prec, v);
  return buf;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string load_average() {
  double l[3] = {0, 0, 0};
  if (std::FILE* f = std::fopen("/proc/loadavg", "r")) {
    if (std::fscanf(f, "%lf %lf %lf", &l[0], &l[1], &l[2]) != 3) l[0] = l[1] = l[2] = -1;
    std::fclose(f);
  }
  return fmt(l[0], 2) + " " + fmt(l[1], 2) + " " + fmt(l[2], 2);
}

}  // namespace

// long on purpose: a bench's main: options, setup, timed runs and its one table, read top to bottom.
int main(int argc, char** argv) {
  Config cfg;
  cfg.scene = bench::source_data_dir() / "scenes" / "bench_peer.json";
  cfg.out_dir = fs::temp_directory_path();
  int repeats = 3;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "bench_threads: " << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--scene") cfg.scene = value();
    else if (a == "-D") cfg.overrides.push_back(render::parse_scene_override(value()));
    else if (a == "--spp") cfg.spp = std::stoll(value());
    else if (a == "--repeats") repeats = std::stoi(value());
    else if (a == "--out") cfg.out_dir = value();
    else {
      std::cerr << "usage: bench_threads [--scene FILE] [-D key=value]... [--spp N] [--repeats 3] [--out DIR]\n";
      return 2;
    }
  }
  try {
    std::cout << "scene " << cfg.scene.string();
    for (const auto& o : cfg.overrides) std::cout << " -D " << o.key << "=" << o.value;
    if (cfg.spp > 0) std::cout << " --spp " << cfg.spp;
    std::cout << "\nload average at start " << load_average() << "\n\n";

    // 1. One thread, CPU time per phase (median of the repeats).
    std::vector<std::vector<double>> cpu(kPhases);
    std::string sum1, sum2;
    for (int r = 0; r < repeats; ++r) {
      const Phases p = run_once(cfg, 1, Clock{true}, &sum1);
      for (int k = 0; k < kPhases; ++k) cpu[k].push_back(p.t[k]);
    }
    double total = 0;
    std::vector<double> med(kPhases);
    for (int k = 0; k < kPhases; ++k) total += med[k] = median(cpu[k]);
    std::cout << "one thread, CPU seconds per phase (median of " << repeats << ")\n";
    for (int k = 0; k < kPhases; ++k)
      std::cout << "  " << kPhaseNames[k] << std::string(10 - std::string(kPhaseNames[k]).size(), ' ') << fmt(med[k], 4)
                << " s  " << fmt(100.0 * med[k] / total, 2) << " %\n";
    std::cout << "  total     " << fmt(total, 4) << " s\n\n";

    // The serial fraction, at most: every phase but the loop counted as serial (load's classification,
    // set-up's majorant grid and write's PIZ encoding run in parallel, so this is an upper bound), from
    // CPU times, which a loaded machine does not inflate. Amdahl: S(2) = 1 / (f + (1 − f)/2).
    const double f = (total - med[2]) / total;
    std::cout << "serial fraction at most " << fmt(100 * f, 2) << " % (all but the loop); Amdahl's bound for 2 threads "
              << "at least " << fmt(1.0 / (f + (1 - f) / 2), 3) << "×\n\n";

    // 2. The whole pipeline on 1 and 2 threads, interleaved, wall time.
    std::vector<std::vector<double>> w1(kPhases), w2(kPhases);
    std::vector<double> t1, t2;
    for (int r = 0; r < repeats; ++r) {
      for (int order = 0; order < 2; ++order) {
        const int threads = (order + r) % 2 == 0 ? 1 : 2;
        const Phases p = run_once(cfg, threads, Clock{false}, threads == 2 ? &sum2 : nullptr);
        for (int k = 0; k < kPhases; ++k) (threads == 1 ? w1 : w2)[k].push_back(p.t[k]);
        (threads == 1 ? t1 : t2).push_back(p.total());
      }
    }
    std::cout << "wall seconds per phase, 1 thread / 2 threads (median of " << repeats << ", interleaved)\n";
    for (int k = 0; k < kPhases; ++k) {
      const double a = median(w1[k]), b = median(w2[k]);
      std::cout << "  " << kPhaseNames[k] << std::string(10 - std::string(kPhaseNames[k]).size(), ' ') << fmt(a, 4)
                << " / " << fmt(b, 4) << " s  (" << fmt(b > 0 ? a / b : 0.0, 2) << "×)\n";
    }
    const double s1 = median(t1), s2 = median(t2);
    std::cout << "  total     " << fmt(s1, 4) << " / " << fmt(s2, 4) << " s\n";
    std::cout << "speed-up 1 → 2 threads (median wall times): " << fmt(s1 / s2, 3) << "×\n";
    std::cout << "same pixels on 1 and 2 threads: " << (sum1 == sum2 ? "yes" : "NO") << " (checksum " << sum1 << ")\n";
    std::cout << "load average at end " << load_average() << "\n";
  } catch (const std::exception& e) {
    std::cerr << "bench_threads: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
