// Relight throughput: XYZ = Σ_l M_l·T_l over a 1024×1024 image with 32 bins and 2 light layers,
// against a plain streaming read (a sum) of the same transport buffers, interleaved in the same run:
// every iteration times the sum, then the relight at every SIMD level of the kernel
// (relight_simd.h), the level the tools dispatch to among them (bench_levels.h).
// Counters: sum_ms, ratio = dispatched relight time / sum time (target ≤ 1.3: the relight is
// memory-bandwidth bound), ratio_L per level L, relight_GBps and sum_GBps (transport bytes read per
// second, dispatched level), and bench_levels.h's ms_L, dispatched_ms, best_ms, dispatched_over_best,
// dispatch_slower; medians over the iterations. Arg: threads (0 = all).
// Also: the fluorescent row pass at every level (BM_FluorescentRelightLevels), fluorescent against
// plain relighting (BM_FluorescentVsPlainRelight), why 512-bit loads made the former AVX-512
// kernel slow (BM_WideLoadAlignment), and the share of a spectral EXR read spent verifying its pixel
// checksum (BM_ReadVsChecksum).
#include <benchmark/benchmark.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_reduce.h>

#include <unistd.h>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#endif

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <memory>
#include <string>

#include "bench_image.h"
#include "bench_levels.h"
#include "prizma/spectral/relight_image.h"
#include "prizma/spectral/relight_matrix.h"
#include "prizma/spectral/relight_simd.h"
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

void BM_RelightVsStreamingSum(benchmark::State& state) {
  const auto limit = bench::limit_threads(state.range(0));
  const double load_start = bench::load_average();
  const spectral::SpectralImage& img = bench_image();
  std::vector<spectral::LightSpectrum> lights = {spectral::parse_light_spectrum("D65"), spectral::parse_light_spectrum("F11")};
  const spectral::RelightMatrix matrix(img.bins, lights, {});
  std::vector<float> xyz(3 * img.pixel_count());
  const double bytes = static_cast<double>(img.lights.size() * img.pixel_count() * kBins * sizeof(float));
  const spectral::SimdLevel dispatched = spectral::detail::relight_simd_level();
  bench::LevelTimes times(spectral::detail::relight_simd_levels());
  std::vector<double> sum_s;
  bench::time_levels(
      state, times, spectral::SimdKernel::Relight, dispatched, [&] { spectral::relight_into(img, matrix, xyz.data()); },
      [&] {  // the streaming read first in every round, so that all see the same machine load
        const auto t0 = std::chrono::steady_clock::now();
        benchmark::DoNotOptimize(streaming_sum(img));
        sum_s.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      });
  const double sum_median = bench::median_of(sum_s);
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
}

// A fixed number of rounds (every level each time; medians): the slow baseline level would make a
// minimum time of the dispatched level alone take minutes.
BENCHMARK(BM_RelightVsStreamingSum)->Arg(1)->Arg(0)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(15);

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
  state.SetLabel(spectral::detail::relight_simd_target_name(spectral::detail::relight_simd_level()));
  std::unique_ptr<tbb::global_control> limit;
  if (state.range(0) > 0) {
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                  static_cast<std::size_t>(state.range(0)));
  }
  const spectral::SpectralImage& plain = fluorescent_bench_image(false);
  const spectral::SpectralImage& fl = fluorescent_bench_image(true);
  std::vector<spectral::LightSpectrum> lights = {spectral::parse_light_spectrum("LED-V1"), spectral::parse_light_spectrum("D65*0.2")};
  const spectral::RelightMatrix matrix(plain.bins, lights, {});
  const spectral::ReradiationWeights k = spectral::reradiation_weights(fl, matrix.options().cmf);
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
    spectral::relight_into(plain, matrix, xyz.data());
    benchmark::ClobberMemory();
    const double c1 = cpu_s();
    auto t1 = std::chrono::steady_clock::now();
    spectral::relight_into(fl, matrix, xyz.data(), &k);
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
  std::vector<spectral::LightSpectrum> lights = {spectral::parse_light_spectrum("LED-V1"), spectral::parse_light_spectrum("D65*0.2")};
  const spectral::RelightMatrix matrix(fl.bins, lights, {});
  const spectral::ReradiationWeights k = spectral::reradiation_weights(fl, matrix.options().cmf);
  std::vector<float> xyz(3 * fl.pixel_count());
  bench::LevelTimes times(spectral::detail::relight_simd_levels());
  bench::time_levels(
      state, times, spectral::SimdKernel::Relight, spectral::detail::relight_simd_level(),
      [&] { spectral::relight_into(fl, matrix, xyz.data(), &k); }, [] {});
}

BENCHMARK(BM_FluorescentRelightLevels)->Arg(1)->Arg(0)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(25);

#if defined(__x86_64__) && defined(__GNUC__)
// Why the former AVX-512 relight was the slowest level on the AMD EPYC of issue 26: its loop (per
// pixel three FMA accumulators, one vector of bins at a time, a horizontal sum each) with 512-bit
// and with 256-bit loads, over a copy of the transport that starts on a 64-byte boundary and one
// that starts 16 bytes past it, as glibc starts a large std::vector (the header of its mmap'd
// chunk): with 32 bins every pixel then starts 16 bytes into a cache line, so every 512-bit load
// spans two lines and one 256-bit load in two. One thread, the four interleaved; CPU time.
// Counters: ms_512_aligned, ms_512_offset16, ms_256_aligned, ms_256_offset16 (medians). Needs AVX-512.
__attribute__((target("avx2,fma"))) float sum_lanes_256(__m256 v) {
  const __m128 h = _mm_add_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
  const __m128 q = _mm_add_ps(h, _mm_movehl_ps(h, h));
  return _mm_cvtss_f32(_mm_add_ss(q, _mm_movehdup_ps(q)));
}
// GCC 12's AVX-512 extract intrinsics (inside _mm512_reduce_add_ps) take an _mm512_undefined_ps()
// operand that its -Wmaybe-uninitialized reports: a false positive of those headers.
#if !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
__attribute__((target("avx512f"))) void wide_relight_512(const float* const* layers, const float* w, std::size_t pixels,
                                                          float* out) {
  for (std::size_t p = 0; p < pixels; ++p) {
    __m512 a0 = _mm512_setzero_ps(), a1 = _mm512_setzero_ps(), a2 = _mm512_setzero_ps();
    for (int l = 0; l < 2; ++l)
      for (int i = 0; i < kBins; i += 16) {
        const __m512 v = _mm512_loadu_ps(layers[l] + p * kBins + static_cast<std::size_t>(i));
        a0 = _mm512_fmadd_ps(_mm512_loadu_ps(w + i), v, a0);
        a1 = _mm512_fmadd_ps(_mm512_loadu_ps(w + kBins + i), v, a1);
        a2 = _mm512_fmadd_ps(_mm512_loadu_ps(w + 2 * kBins + i), v, a2);
      }
    out[3 * p] = _mm512_reduce_add_ps(a0);
    out[3 * p + 1] = _mm512_reduce_add_ps(a1);
    out[3 * p + 2] = _mm512_reduce_add_ps(a2);
  }
}
#if !defined(__clang__)
#pragma GCC diagnostic pop
#endif
__attribute__((target("avx2,fma"))) void wide_relight_256(const float* const* layers, const float* w, std::size_t pixels,
                                                           float* out) {
  for (std::size_t p = 0; p < pixels; ++p) {
    __m256 a0 = _mm256_setzero_ps(), a1 = _mm256_setzero_ps(), a2 = _mm256_setzero_ps();
    for (int l = 0; l < 2; ++l)
      for (int i = 0; i < kBins; i += 8) {
        const __m256 v = _mm256_loadu_ps(layers[l] + p * kBins + static_cast<std::size_t>(i));
        a0 = _mm256_fmadd_ps(_mm256_loadu_ps(w + i), v, a0);
        a1 = _mm256_fmadd_ps(_mm256_loadu_ps(w + kBins + i), v, a1);
        a2 = _mm256_fmadd_ps(_mm256_loadu_ps(w + 2 * kBins + i), v, a2);
      }
    out[3 * p] = sum_lanes_256(a0);
    out[3 * p + 1] = sum_lanes_256(a1);
    out[3 * p + 2] = sum_lanes_256(a2);
  }
}

void BM_WideLoadAlignment(benchmark::State& state) {
  if (!__builtin_cpu_supports("avx512f")) {
    state.SkipWithError("no AVX-512 on this CPU");
    return;
  }
  const spectral::SpectralImage& img = bench_image();
  const std::size_t n = img.pixel_count() * kBins;
  // Both layers at float offset 0 (64-byte aligned) and 4 (16 bytes past) of 64-byte aligned buffers.
  struct Copy {
    float* base = nullptr;
    const float* layers[2] = {nullptr, nullptr};
  };
  Copy copies[2];
  for (int o = 0; o < 2; ++o) {
    copies[o].base = static_cast<float*>(std::aligned_alloc(64, 2 * (n + 16) * sizeof(float)));
    for (int l = 0; l < 2; ++l) {
      float* dst = copies[o].base + static_cast<std::size_t>(l) * (n + 16) + (o == 0 ? 0 : 4);
      std::memcpy(dst, img.lights[static_cast<std::size_t>(l)].data.data(), n * sizeof(float));
      copies[o].layers[l] = dst;
    }
  }
  alignas(64) float w[3 * kBins];
  for (int i = 0; i < 3 * kBins; ++i) w[i] = 0.01f * static_cast<float>(i % 7 + 1);
  std::vector<float> out(3 * img.pixel_count());
  std::vector<double> ms[4];  // 512 aligned, 512 +16, 256 aligned, 256 +16
  for (auto _ : state) {
    for (int k = 0; k < 4; ++k) {
      const double c0 = bench::process_cpu_seconds();
      (k < 2 ? wide_relight_512 : wide_relight_256)(copies[k % 2].layers, w, img.pixel_count(), out.data());
      benchmark::ClobberMemory();
      ms[k].push_back(1e3 * (bench::process_cpu_seconds() - c0));
    }
  }
  for (Copy& c : copies) std::free(c.base);
  const char* names[4] = {"ms_512_aligned", "ms_512_offset16", "ms_256_aligned", "ms_256_offset16"};
  for (int k = 0; k < 4; ++k) state.counters[names[k]] = bench::median_of(ms[k]);
}

BENCHMARK(BM_WideLoadAlignment)->Unit(benchmark::kMillisecond)->Iterations(10);
#endif

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
