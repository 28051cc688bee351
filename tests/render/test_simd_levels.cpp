// The tracer at every SIMD level this CPU runs (simd_level.h) returns the same bits as the baseline
// build: every example scene, all-bins and one-lane paths, every event-probability scheme. A level
// the CPU lacks is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "prizma/render/camera.h"
#include "prizma/render/path_tracer.h"
#include "prizma/render/rng.h"
#include "prizma/render/scene.h"
#include "prizma/render/simd_level.h"
#include "prizma/spectral/error.h"

namespace prizma::render {
namespace {

// Everything trace() returned for a batch of paths, as floats in a fixed order, and the counters.
struct Transport {
  std::vector<float> values;
  std::vector<std::int64_t> counters;
};

void append(std::vector<float>& to, const std::vector<float>& v) { to.insert(to.end(), v.begin(), v.end()); }

// Traces `samples` paths through each pixel of an 8×8 view of the scene with `lanes` lanes (the
// bins' centres jittered by the path's random numbers, as render() draws them).
Transport trace_batch(const Scene& scene, const PathTracer& tracer, int lanes, int samples) {
  Camera cam = scene.camera;
  cam.width = 8;
  cam.height = 8;
  const CameraModel camera(cam);
  const spectral::BinLayout& bins = scene.settings.bins;
  PathScratch s;
  tracer.prepare(s, lanes);
  for (int i = 0; i < lanes; ++i) {
    s.in.lo_nm[i] = static_cast<float>(bins.lo_nm(i % bins.size()));
    s.in.width_nm[i] = lanes == 1 ? 0.0f : static_cast<float>(bins.width_nm(i));
  }
  Transport t;
  for (int py = 0; py < cam.height; ++py)
    for (int px = 0; px < cam.width; ++px)
      for (int k = 0; k < samples; ++k) {
        Rng rng(scene.settings.seed, static_cast<std::uint64_t>(py * cam.width + px), static_cast<std::uint64_t>(k));
        const double u = rng.uniform_double();
        for (int i = 0; i < lanes; ++i) {
          const double lo = bins.lo_nm(i % bins.size()), width = bins.width_nm(i % bins.size());
          s.in.lambda_nm[i] = static_cast<float>(lo + u * width);
        }
        tracer.trace(camera.generate(px + rng.uniform_double(), py + rng.uniform_double()), rng, s);
        append(t.values, s.out.environment);
        append(t.values, s.out.emission);
        append(t.values, s.out.directional);
        t.values.push_back(s.out.fl_active ? 1.0f : 0.0f);
        if (s.out.fl_active) {
          append(t.values, s.out.fl_a);
          append(t.values, s.out.fl_environment);
          append(t.values, s.out.fl_emission);
          append(t.values, s.out.fl_directional);
        }
      }
  t.counters = {s.counters.paths_in_volume, s.counters.collisions, s.counters.shadow_steps, s.counters.majorant_cells};
  return t;
}

// The first value that differs bit for bit, or −1.
long first_difference(const std::vector<float>& a, const std::vector<float>& b) {
  if (a.size() != b.size()) return 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::memcmp(&a[i], &b[i], sizeof(float)) != 0) return static_cast<long>(i);
  return -1;
}

std::vector<std::filesystem::path> example_scenes() {
  std::vector<std::filesystem::path> out;
  for (const auto& e : std::filesystem::directory_iterator(std::filesystem::path(PRIZMA_TEST_DATA_DIR) / "scenes")) {
    if (e.path().extension() != ".json") continue;
    std::ifstream in(e.path());
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (text.find("/usr/share/mricron/") != std::string::npos && !std::filesystem::exists("/usr/share/mricron/")) {
      std::cout << "skipping " << e.path() << ": mricron-data is not installed\n";
      continue;
    }
    out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(SimdLevels, BaselineAlwaysSupportedAndNamesRoundTrip) {
  const std::vector<SimdLevel> levels = supported_simd_levels();
  ASSERT_FALSE(levels.empty());
  EXPECT_EQ(levels.front(), SimdLevel::Baseline);
  EXPECT_TRUE(std::is_sorted(levels.begin(), levels.end()));
  for (SimdLevel l : {SimdLevel::Baseline, SimdLevel::Avx2, SimdLevel::Avx512})
    EXPECT_EQ(parse_simd_level(simd_level_name(l), "test"), l);
  EXPECT_THROW(parse_simd_level("sse9", "PRIZMA_SIMD"), spectral::InputError);
}

TEST(SimdLevels, ATracerStartsAtTheChosenLevel) {
  // spectral::choose_simd_level for SimdKernel::Tracer: forced here (PRIZMA_SIMD or a rule the same way).
  const Scene scene = load_scene(std::filesystem::path(PRIZMA_TEST_DATA_DIR) / "scenes" / "bench_peer.json");
  for (SimdLevel l : supported_simd_levels()) {
    const spectral::ForcedSimdLevel forced(spectral::SimdKernel::Tracer, l);
    EXPECT_EQ(default_simd_level(), l);
    EXPECT_EQ(PathTracer(scene, 400, 700, true).simd_level(), l) << simd_level_name(l);
  }
  const spectral::ForcedSimdLevel sse4(spectral::SimdKernel::Tracer, SimdLevel::Sse4);
  EXPECT_EQ(default_simd_level(), SimdLevel::Baseline) << "no SSE4 level: the one below";
}

TEST(SimdLevels, UnsupportedLevelIsRefused) {
  const Scene scene = load_scene(std::filesystem::path(PRIZMA_TEST_DATA_DIR) / "scenes" / "bench_peer.json");
  PathTracer tracer(scene, 400, 700, true);
  const std::vector<SimdLevel> levels = supported_simd_levels();
  for (SimdLevel l : {SimdLevel::Avx2, SimdLevel::Avx512}) {
    if (std::find(levels.begin(), levels.end(), l) != levels.end()) {
      tracer.set_simd_level(l);
      EXPECT_EQ(tracer.simd_level(), l);
    } else {
      EXPECT_THROW(tracer.set_simd_level(l), spectral::InputError) << simd_level_name(l);
    }
  }
}

TEST(SimdLevels, EveryLevelTracesTheBaselinesBits) {
  const std::vector<SimdLevel> levels = supported_simd_levels();
  if (levels.size() == 1) std::cout << "only the baseline level runs on this CPU: nothing to compare\n";
  const auto scenes = example_scenes();
  ASSERT_GE(scenes.size(), 3u);
  std::size_t compared = 0;
  for (const auto& path : scenes) {
    const Scene loaded = load_scene(path);
    for (EventProbabilities ev : {EventProbabilities::Auto, EventProbabilities::Average, EventProbabilities::Mixed,
                                  EventProbabilities::Implicit}) {
      Scene scene = loaded;
      scene.settings.event_probabilities = ev;
      const spectral::BinLayout& bins = scene.settings.bins;
      PathTracer tracer(scene, bins.min_nm(), bins.max_nm(), scene.settings.use_majorant_grid);
      for (int lanes : {bins.size(), 1}) {
        SCOPED_TRACE(path.filename().string() + ", " + event_probabilities_name(ev) + ", " + std::to_string(lanes) +
                     " lanes");
        tracer.set_simd_level(SimdLevel::Baseline);
        const Transport ref = trace_batch(scene, tracer, lanes, 3);
        ASSERT_GT(ref.values.size(), 0u);
        for (SimdLevel l : levels) {
          if (l == SimdLevel::Baseline) continue;
          tracer.set_simd_level(l);
          const Transport got = trace_batch(scene, tracer, lanes, 3);
          EXPECT_EQ(first_difference(ref.values, got.values), -1) << simd_level_name(l);
          EXPECT_EQ(ref.counters, got.counters) << simd_level_name(l);
          ++compared;
        }
      }
    }
  }
  if (levels.size() > 1) {
    EXPECT_GE(compared, scenes.size() * 8 * (levels.size() - 1));
  }
}

}  // namespace
}  // namespace prizma::render
