// Relight throughput: XYZ = Σ_l M_l·T_l over a 1024×1024 image with 32 bins and 2 light layers,
// against a plain streaming read (a sum) of the same transport buffers, interleaved in the same run.
// Counters: relight_GBps and sum_GBps (transport bytes read per second) and ratio = relight time /
// sum time (target ≤ 1.3: the relight is memory-bandwidth bound). Arg: threads (0 = all). The
// variants force one SIMD target of the kernel's run-time dispatch (relight_simd.cpp): "best" is
// what the tools use on this CPU; AVX2 and SSE4 (128-bit, the width of the former SSE2 build) are
// for comparison inside the same run.
// Also: the share of a spectral EXR read spent verifying its pixel checksum (BM_ReadVsChecksum).
#include <benchmark/benchmark.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_reduce.h>

#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>

#include "bench_image.h"
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

void BM_RelightVsStreamingSum(benchmark::State& state, const std::string& target) {
  relight::detail::relight_simd_force_target(target);
  state.SetLabel(relight::detail::relight_simd_target());
  const auto limit = bench::limit_threads(state.range(0));
  const spectral::SpectralImage& img = bench_image();
  std::vector<relight::LightSpec> lights = {relight::parse_light_spec("D65"), relight::parse_light_spec("F11")};
  const relight::RelightMatrix matrix(img.bins, lights, {});
  std::vector<float> xyz(3 * img.pixel_count());
  const double bytes = static_cast<double>(img.lights.size() * img.pixel_count() * kBins * sizeof(float));
  double relight_s = 0.0, sum_s = 0.0;
  for (auto _ : state) {
    // Interleaved so that both see the same machine load.
    auto t0 = std::chrono::steady_clock::now();
    benchmark::DoNotOptimize(streaming_sum(img));
    auto t1 = std::chrono::steady_clock::now();
    relight::relight_into(img, matrix, xyz.data());
    benchmark::ClobberMemory();
    auto t2 = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(t1 - t0).count();
    const double r = std::chrono::duration<double>(t2 - t1).count();
    sum_s += s;
    relight_s += r;
    state.SetIterationTime(r);
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["relight_GBps"] = bytes * n / relight_s / 1e9;
  state.counters["sum_GBps"] = bytes * n / sum_s / 1e9;
  state.counters["ratio"] = relight_s / sum_s;
  state.counters["relight_ms"] = 1e3 * relight_s / n;
  state.counters["sum_ms"] = 1e3 * sum_s / n;
  state.SetBytesProcessed(static_cast<std::int64_t>(bytes * n));
  relight::detail::relight_simd_force_target("");
}

BENCHMARK_CAPTURE(BM_RelightVsStreamingSum, best, std::string())
    ->Arg(0)->Arg(1)->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_CAPTURE(BM_RelightVsStreamingSum, AVX2, std::string("AVX2"))
    ->Arg(0)->Arg(1)->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_CAPTURE(BM_RelightVsStreamingSum, SSE4, std::string("SSE4"))
    ->Arg(0)->Arg(1)->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(2.0);

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
