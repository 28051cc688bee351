// Relight throughput: XYZ = Σ_l M_l·T_l over a 1024×1024 image with 32 bins and 2 light layers,
// against a plain streaming read (a sum) of the same transport buffers, interleaved in the same run:
// every iteration times the sum, then the relight at every SIMD level of the kernel
// (relight_simd.h), the level the tools dispatch to among them (bench_levels.h).
// Counters: sum_ms, ratio = dispatched relight time / sum time (target ≤ 1.3: the relight is
// memory-bandwidth bound), ratio_L per level L, relight_GBps and sum_GBps (transport bytes read per
// second, dispatched level), and bench_levels.h's ms_L, dispatched_ms, best_ms, dispatched_over_best,
// dispatch_slower; medians over the iterations. Arg: threads (0 = all).
// Also: the fluorescent row pass at every level (BM_FluorescentRelightLevels), fluorescent against
// plain relighting (BM_FluorescentVsPlainRelight), and the share of a spectral EXR read spent
// verifying its pixel checksum (BM_ReadVsChecksum).
#include <benchmark/benchmark.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_reduce.h>

#include <unistd.h>

#include <chrono>
#include <ctime>
#include <filesystem>
#include <memory>
#include <string>

#include "bench_image.h"
#include "bench_levels.h"
#include "prizma/relight/relight_image.h"
#include "prizma/relight/relight_matrix.h"
#include "prizma/relight/relight_simd.h"
#include "prizma/spectral/spectral_exr.h"

namespace {

using namespace prizma;

constexpr int kSize = 1024;
constexpr int kBins = 32;

const spectral::SpectralImage& bench_image() {
  static const spectral::SpectralImage image =
      bench::make_bench_image(kSize, kSize, spectral::BinLayout::linear(380.0, 780.0, kBins), bench::BenchSpectra::Uniform);
  return image;
}

// The baseline: one streaming pass summing every transport value, parallel over rows like the relight.
double streaming_sum(const spectral::SpectralImage& img) {
  const std::size_t row = static_cast<std::size_t>(img.width) * kBins;
  return tbb::parallel_reduce(
      tbb::blocked_range<int>(0, img.height), 0.0,
      [&](const tbb::blocked_range<int>& rows, double acc) {
        for (const auto& layer : img.lights) {
          const float* p = layer.data.data() + static_cast<std::size_t>(rows.begin()) * row;
          const float* end = layer.data.data() + static_cast<std::size_t>(rows.end()) * row;
          float s[8] = {0, 0, 0, 0, 0, 0, 0, 0};
          for (; p != end; p += 8)
            for (int k = 0; k < 8; ++k) s[k] += p[k];
          for (float v : s) acc += v;
        }
        return acc;
      },
      [](double a, double b) { return a + b; });
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The median of `v` (not empty).
double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

void BM_RelightVsStreamingSum(benchmark::State& state) {
  const auto limit = bench::limit_threads(state.range(0));
  const double load_start = bench::load_average();
  const spectral::SpectralImage& img = bench_image();
  std::vector<relight::LightSpec> lights = {relight::parse_light_spec("D65"), relight::parse_light_spec("F11")};
  const relight::RelightMatrix matrix(img.bins, lights, {});
  std::vector<float> xyz(3 * img.pixel_count());
  const double bytes = static_cast<double>(img.lights.size() * img.pixel_count() * kBins * sizeof(float));
  const spectral::SimdLevel dispatched = relight::detail::relight_simd_level();
  bench::LevelTimes times(relight::detail::relight_simd_levels());
  std::vector<double> sum_s;
  for (auto _ : state) {
    // Interleaved so that all see the same machine load.
    const auto t0 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(streaming_sum(img));
    sum_s.push_back(seconds_since(t0));
    double dispatched_s = 0.0;
    for (std::size_t i = 0; i < times.levels().size(); ++i) {
      const spectral::ForcedSimdLevel forced(spectral::SimdKernel::Relight, times.levels()[i]);
      const auto t1 = std::chrono::steady_clock::now();
      relight::relight_into(img, matrix, xyz.data());
      benchmark::ClobberMemory();
      const double r = seconds_since(t1);
      times.add(i, r);
      if (times.levels()[i] == dispatched) dispatched_s = r;
    }
    state.SetIterationTime(dispatched_s);
  }
  const double sum_median = median(sum_s);
  const double relight_median = times.median(times.index_of(dispatched));
  state.counters["sum_ms"] = 1e3 * sum_median;
  state.counters["ratio"] = relight_median / sum_median;
  for (std::size_t i = 0; i < times.levels().size(); ++i)
    state.counters["ratio_" + std::string(spectral::simd_level_name(times.levels()[i]))] = times.median(i) / sum_median;
  state.counters["relight_GBps"] = bytes / relight_median / 1e9;
  state.counters["sum_GBps"] = bytes / sum_median / 1e9;
  state.counters["load_start"] = load_start;
  state.counters["load_end"] = bench::load_average();
  state.SetBytesProcessed(static_cast<std::int64_t>(bytes * static_cast<double>(state.iterations())));
  times.report(state, dispatched);
}

BENCHMARK(BM_RelightVsStreamingSum)->Arg(1)->Arg(0)->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(1.0);

// Fluorescent against plain relighting, interleaved in one run: a 512×512 image with 32 bins over
// 380–780 nm and 2 lights, once without and once with bispectral terms (the 12 bins below 530 nm
// re-emitting into bins 16, 20, 24 and 28: 48 pairs, |in| = 12, so K adds 3·12 floats per pixel and
// light to the diagonal's 32). K is computed once (as the interactive session and
// the live page keep it); each iteration relights both images under the same lights. Counters:
// ratio = fluorescent / plain CPU time of the process (CLOCK_PROCESS_CPUTIME_ID), traffic = floats
// read (and written) per pixel fluorescent / plain (the goal: ratio ≈ traffic), wall_ratio the same
// in wall time, and the CPU times. CPU time because on a loaded machine the wall time of a relight
// longer than the scheduler's time slice includes the wait for the next one (a 3 ms relight then
// takes 30 ms of wall time at load 13, a 1.4 ms one does not: docs/results.md, "Fluorescence").
// Arg: threads (0 = all; 1 gives the cleanest CPU times).
const spectral::SpectralImage& fluorescent_bench_image(bool with_reradiation) {
  static const std::vector<spectral::SpectralImage> images = [] {
    spectral::SpectralImage img;
    img.width = kSize / 2;
    img.height = kSize / 2;
    img.bins = spectral::BinLayout::linear(380.0, 780.0, kBins);
    std::mt19937 rng(54321);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (const char* name : {"key", "back"}) {
      spectral::TransportLayer layer;
      layer.name = name;
      layer.data.resize(img.pixel_count() * kBins);
      for (float& v : layer.data) v = u(rng);
      img.lights.push_back(std::move(layer));
    }
    spectral::SpectralImage fl = img;
    for (int in = 0; in < 12; ++in)
      for (int out : {16, 20, 24, 28}) fl.reradiation.push_back({in, out});
    for (auto& layer : fl.lights) {
      layer.reradiation.resize(fl.pixel_count() * fl.reradiation.size());
      for (float& v : layer.reradiation) v = 0.05f * u(rng);
    }
    return std::vector<spectral::SpectralImage>{std::move(img), std::move(fl)};
  }();
  return images[with_reradiation ? 1 : 0];
}

void BM_FluorescentVsPlainRelight(benchmark::State& state) {
  state.SetLabel(relight::detail::relight_simd_target_name(relight::detail::relight_simd_level()));
  std::unique_ptr<tbb::global_control> limit;
  if (state.range(0) > 0) {
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                  static_cast<std::size_t>(state.range(0)));
  }
  const spectral::SpectralImage& plain = fluorescent_bench_image(false);
  const spectral::SpectralImage& fl = fluorescent_bench_image(true);
  std::vector<relight::LightSpec> lights = {relight::parse_light_spec("LED-V1"), relight::parse_light_spec("D65*0.2")};
  const relight::RelightMatrix matrix(plain.bins, lights, {});
  const relight::ReradiationWeights k = relight::reradiation_weights(fl, matrix.options().cmf);
  std::vector<float> xyz(3 * plain.pixel_count());
  const auto cpu_s = [] {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
  };
  double plain_s = 0.0, fl_s = 0.0, plain_wall = 0.0, fl_wall = 0.0;
  for (auto _ : state) {
    const double c0 = cpu_s();
    auto t0 = std::chrono::steady_clock::now();
    relight::relight_into(plain, matrix, xyz.data());
    benchmark::ClobberMemory();
    const double c1 = cpu_s();
    auto t1 = std::chrono::steady_clock::now();
    relight::relight_into(fl, matrix, xyz.data(), &k);
    benchmark::ClobberMemory();
    const double c2 = cpu_s();
    auto t2 = std::chrono::steady_clock::now();
    plain_s += c1 - c0;
    fl_s += c2 - c1;
    plain_wall += std::chrono::duration<double>(t1 - t0).count();
    fl_wall += std::chrono::duration<double>(t2 - t1).count();
    state.SetIterationTime(std::chrono::duration<double>(t2 - t1).count());
  }
  const double n = static_cast<double>(state.iterations());
  const double diag = static_cast<double>(plain.lights.size() * kBins);
  const double rerad = static_cast<double>(fl.lights.size() * 3 * k.in_bins.size());
  state.counters["ratio"] = fl_s / plain_s;
  state.counters["wall_ratio"] = fl_wall / plain_wall;
  state.counters["traffic"] = (diag + rerad + 3.0) / (diag + 3.0);  // floats read (+ 3 written) per pixel
  state.counters["fluorescent_cpu_ms"] = 1e3 * fl_s / n;
  state.counters["plain_cpu_ms"] = 1e3 * plain_s / n;
}

BENCHMARK(BM_FluorescentVsPlainRelight)->Arg(0)->Arg(1)->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(2.0);

// The fluorescent row pass at every SIMD level, interleaved: the image above with its bispectral
// terms (per light a second term of 3·12 = 36 values per pixel: two whole blocks of 16 and a partial
// one), K kept as above. Wall time; bench_levels.h's counters. Arg: threads (0 = all).
void BM_FluorescentRelightLevels(benchmark::State& state) {
  const auto limit = bench::limit_threads(state.range(0));
  const spectral::SpectralImage& fl = fluorescent_bench_image(true);
  std::vector<relight::LightSpec> lights = {relight::parse_light_spec("LED-V1"), relight::parse_light_spec("D65*0.2")};
  const relight::RelightMatrix matrix(fl.bins, lights, {});
  const relight::ReradiationWeights k = relight::reradiation_weights(fl, matrix.options().cmf);
  std::vector<float> xyz(3 * fl.pixel_count());
  const spectral::SimdLevel dispatched = relight::detail::relight_simd_level();
  bench::LevelTimes times(relight::detail::relight_simd_levels());
  for (auto _ : state) {
    double dispatched_s = 0.0;
    for (std::size_t i = 0; i < times.levels().size(); ++i) {
      const spectral::ForcedSimdLevel forced(spectral::SimdKernel::Relight, times.levels()[i]);
      const auto t0 = std::chrono::steady_clock::now();
      relight::relight_into(fl, matrix, xyz.data(), &k);
      benchmark::ClobberMemory();
      const double r = seconds_since(t0);
      times.add(i, r);
      if (times.levels()[i] == dispatched) dispatched_s = r;
    }
    state.SetIterationTime(dispatched_s);
  }
  times.report(state, dispatched);
}

BENCHMARK(BM_FluorescentRelightLevels)->Arg(1)->Arg(0)->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(1.0);

// What verifying prizma:checksum costs when a file is read: read_spectral_exr of a 512×512, 32-bin,
// two-light float file (its time includes the verification) against spectral_pixel_checksum of the
// same image alone, interleaved. Counter checksum_share = checksum time / read time.
void BM_ReadVsChecksum(benchmark::State& state) {
  const spectral::SpectralImage& full = bench_image();
  spectral::SpectralImage img;
  img.width = img.height = kSize / 2;
  img.bins = full.bins;
  for (const auto& light : full.lights) {
    spectral::TransportLayer layer;
    layer.name = light.name;
    layer.data.assign(light.data.begin(), light.data.begin() + static_cast<std::ptrdiff_t>(img.pixel_count() * kBins));
    img.lights.push_back(std::move(layer));
  }
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("prizma-bench-read-" + std::to_string(::getpid()) + ".exr");
  spectral::write_spectral_exr(path, img);
  double read_s = 0.0, sum_s = 0.0;
  for (auto _ : state) {
    auto t0 = std::chrono::steady_clock::now();
    const spectral::SpectralImage back = spectral::read_spectral_exr(path);
    auto t1 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(spectral::spectral_pixel_checksum(back));
    auto t2 = std::chrono::steady_clock::now();
    read_s += std::chrono::duration<double>(t1 - t0).count();
    sum_s += std::chrono::duration<double>(t2 - t1).count();
    state.SetIterationTime(std::chrono::duration<double>(t1 - t0).count());
  }
  std::filesystem::remove(path);
  const double n = static_cast<double>(state.iterations());
  state.counters["read_ms"] = 1e3 * read_s / n;
  state.counters["checksum_ms"] = 1e3 * sum_s / n;
  state.counters["checksum_share"] = sum_s / read_s;
}

BENCHMARK(BM_ReadVsChecksum)->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(3.0);

}  // namespace

BENCHMARK_MAIN();
