// Compressed transport at 4K: a 3840×2160, 2-light, 16-bin image to display-ready 8-bit sRGB per
// frame, exact (relight_into over the bins, as prizma-relight does) against compressed
// (relight_compressed_into over k coefficients per light), both through the same DisplayEncoder8
// (the shipped OCIO config's sRGB display, matrix applied and curve baked), interleaved in one run.
// Counters: exact_ms, compressed_ms (whole frame), their relight and encode parts, ratio =
// exact ÷ compressed, fused_ms (relight_compressed_to_display8, the manual time reported) with
// fused_cpu_ms (its CPU time, all threads), exact_over_fused and unfused_over_fused, coefficients_MB (the half coefficients a frame reads) and
// fused_GBps (those and the 8-bit codes written, per second of the fused frame), the load average at
// start and end, k per light, and the compressed frame's error against the exact one: ΔE00
// p99 and max over all pixels (Lab relative to the mix's white) and the 8-bit codes that differ.
// Arg: threads (0 = all).
// BM_CompressedFrameLevels / BM_HalfToFloatLevels: the fused frame and relight_compressed_into (its
// half → float rows) at every SIMD level, interleaved, with bench_levels.h's counters.
//
// `bench_compressed --scene FILE.exr` instead prints, per light of a spectral EXR, the k chosen and
// the ΔE00 p99 / max under D65, A, F11 and gaussian:450:20 (docs/results.md's per-scene table).
#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <memory>
#include <random>
#include <string>

#include "bench_image.h"
#include "bench_levels.h"
#include "prizma/relight/compressed_relight.h"
#include "prizma/spectral/relight_image.h"
#include "prizma/relight/kernel_levels.h"
#include "prizma/relight/light_spec.h"
#include "prizma/spectral/colour.h"
#include "prizma/spectral/spectral_exr.h"

namespace {

using namespace prizma;

constexpr int kWidth = 3840;
constexpr int kHeight = 2160;
constexpr int kBins = 16;

// Smooth spectra that vary over the image (four Gaussian shapes mixed by smooth weights) with ±0.0005
// uniform noise: a converged render's transport, not a noisy one (bench_image.h).
const spectral::SpectralImage& bench_image() {
  static const spectral::SpectralImage image = bench::make_bench_image(
      kWidth, kHeight, spectral::BinLayout::linear(400.0, 700.0, kBins), bench::BenchSpectra::Smooth);
  return image;
}

const relight::CompressedTransport& bench_transport() {
  static const relight::CompressedTransport t = relight::compress_transport(bench_image());
  return t;
}

// CPU time of the whole process (every thread), seconds.
double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double percentile(std::vector<double> v, double q) {
  const std::size_t i = std::min(v.size() - 1, static_cast<std::size_t>(std::ceil(q / 100.0 * static_cast<double>(v.size()))) - 1);
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(i), v.end());
  return v[i];
}

// long on purpose: a bench: one fixture's setup and the timed loop with its counters.
void BM_ExactVsCompressed4K(benchmark::State& state) {
  const auto limit = bench::limit_threads(state.range(0));
  const double load_start = bench::load_average();
  const spectral::SpectralImage& img = bench_image();
  const relight::CompressedTransport& comp = bench_transport();
  const std::vector<relight::LightSpec> lights = {relight::parse_light_spec("D65"), relight::parse_light_spec("F11")};
  const spectral::RelightMatrix matrix(img.bins, lights, {});
  const spectral::DisplayTransform display(spectral::DisplayOptions{});
  const relight::DisplayEncoder8 encoder(display);
  std::vector<float> xyz_exact(3 * img.pixel_count()), xyz_comp(3 * img.pixel_count());
  std::vector<std::uint8_t> rgb_exact(3 * img.pixel_count()), rgb_comp(3 * img.pixel_count()),
      rgb_fused(3 * img.pixel_count());
  double exact_relight = 0, exact_encode = 0, comp_relight = 0, comp_encode = 0, fused = 0, fused_cpu = 0;
  using clock = std::chrono::steady_clock;
  auto secs = [](clock::time_point a, clock::time_point b) { return std::chrono::duration<double>(b - a).count(); };
  for (auto _ : state) {
    const auto t0 = clock::now();
    spectral::relight_into(img, matrix, xyz_exact.data());
    const auto t1 = clock::now();
    encoder.encode(xyz_exact.data(), img.pixel_count(), rgb_exact.data());
    const auto t2 = clock::now();
    relight::relight_compressed_into(comp, matrix, xyz_comp.data());
    const auto t3 = clock::now();
    encoder.encode(xyz_comp.data(), img.pixel_count(), rgb_comp.data());
    const auto t4 = clock::now();
    const double cpu4 = process_cpu_seconds();
    relight::relight_compressed_to_display8(comp, matrix, encoder, rgb_fused.data());
    const auto t5 = clock::now();
    fused_cpu += process_cpu_seconds() - cpu4;
    benchmark::ClobberMemory();
    exact_relight += secs(t0, t1);
    exact_encode += secs(t1, t2);
    comp_relight += secs(t2, t3);
    comp_encode += secs(t3, t4);
    fused += secs(t4, t5);
    state.SetIterationTime(secs(t4, t5));
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["exact_ms"] = 1e3 * (exact_relight + exact_encode) / n;
  state.counters["exact_relight_ms"] = 1e3 * exact_relight / n;
  state.counters["compressed_ms"] = 1e3 * (comp_relight + comp_encode) / n;
  state.counters["compressed_relight_ms"] = 1e3 * comp_relight / n;
  state.counters["encode_ms"] = 1e3 * (exact_encode + comp_encode) / (2 * n);
  state.counters["ratio"] = (exact_relight + exact_encode) / (comp_relight + comp_encode);
  // The fused frame (relight_compressed_to_display8: one pass, display matrix folded in, step table,
  // Highway SIMD): its ms, exact frame ÷ fused and unfused compressed frame ÷ fused.
  state.counters["fused_ms"] = 1e3 * fused / n;
  state.counters["fused_cpu_ms"] = 1e3 * fused_cpu / n;  // CPU time of all threads: less sensitive to load
  state.counters["exact_over_fused"] = (exact_relight + exact_encode) / fused;
  state.counters["unfused_over_fused"] = (comp_relight + comp_encode) / fused;
  // What the fused frame moves: the half coefficients read once, the 8-bit codes written.
  double coefficient_bytes = 0;
  for (const auto& layer : comp.lights) coefficient_bytes += static_cast<double>(layer.coefficients.size() * sizeof(layer.coefficients[0]));
  state.counters["coefficients_MB"] = coefficient_bytes / 1e6;
  state.counters["fused_GBps"] = (coefficient_bytes + static_cast<double>(rgb_fused.size())) * n / fused / 1e9;
  state.counters["step_table"] = static_cast<double>(encoder.step_table().entries[0].size());  // 0: none (unfused)
  state.counters["step_shift"] = encoder.step_table().shift;
  state.counters["load_start"] = load_start;
  state.counters["load_end"] = bench::load_average();
  state.counters["baked"] = encoder.baked() ? 1 : 0;
  for (std::size_t l = 0; l < comp.lights.size(); ++l) state.counters["k_" + comp.lights[l].name] = comp.lights[l].k;
  // Errors of the last compressed frame against the exact one, every pixel.
  const Eigen::Vector3d white = matrix.mix_white_xyz();
  std::vector<double> de(img.pixel_count());
  for (std::size_t p = 0; p < img.pixel_count(); ++p) {
    const Eigen::Vector3d a(xyz_exact[3 * p], xyz_exact[3 * p + 1], xyz_exact[3 * p + 2]);
    const Eigen::Vector3d b(xyz_comp[3 * p], xyz_comp[3 * p + 1], xyz_comp[3 * p + 2]);
    de[p] = spectral::delta_e2000(spectral::xyz_to_lab(a, white), spectral::xyz_to_lab(b, white));
  }
  state.counters["dE00_max"] = *std::max_element(de.begin(), de.end());
  state.counters["dE00_p99"] = percentile(std::move(de), 99.0);
  std::size_t differ = 0;
  int worst = 0;
  for (std::size_t i = 0; i < rgb_exact.size(); ++i) {
    const int d = std::abs(int{rgb_exact[i]} - int{rgb_comp[i]});
    differ += d != 0;
    worst = std::max(worst, d);
  }
  state.counters["codes_differ_pct"] = 100.0 * static_cast<double>(differ) / static_cast<double>(rgb_exact.size());
  state.counters["codes_max_diff"] = worst;
  std::size_t fused_differ = 0;
  int fused_worst = 0;
  for (std::size_t i = 0; i < rgb_comp.size(); ++i) {
    const int d = std::abs(int{rgb_fused[i]} - int{rgb_comp[i]});
    fused_differ += d != 0;
    fused_worst = std::max(fused_worst, d);
  }
  state.counters["fused_vs_unfused_differ_pct"] = 100.0 * static_cast<double>(fused_differ) / static_cast<double>(rgb_comp.size());
  state.counters["fused_vs_unfused_max_diff"] = fused_worst;
}

BENCHMARK(BM_ExactVsCompressed4K)->Arg(2)->Arg(1)->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(3.0);

// The one-off cost of compressing the 4K image (Gram, eigendecomposition, choice of k, projection).
void BM_Compress4K(benchmark::State& state) {
  const spectral::SpectralImage& img = bench_image();
  for (auto _ : state) benchmark::DoNotOptimize(relight::compress_transport(img));
}

BENCHMARK(BM_Compress4K)->Unit(benchmark::kMillisecond)->Iterations(1);

// For the SIMD levels: a 1920×1080 transport of 2 lights with k = 4 half coefficients each (what
// the 4K image above gets), random, made directly rather than by compressing (a short set-up).
const relight::CompressedTransport& level_transport() {
  static const relight::CompressedTransport t = [] {
    relight::CompressedTransport out;
    out.width = 1920;
    out.height = 1080;
    out.bins = spectral::BinLayout::linear(400.0, 700.0, kBins);
    std::mt19937 rng(26);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (const char* name : {"key", "back"}) {
      relight::CompressedLayer layer;
      layer.name = name;
      const Eigen::MatrixXf basis = Eigen::MatrixXf::NullaryExpr(kBins, 4, [&] { return 0.25f * u(rng); });
      std::vector<float> c(out.pixel_count() * 4);
      for (float& v : c) v = u(rng);
      relight::set_half_coefficients(layer, basis, c);
      out.lights.push_back(std::move(layer));
    }
    return out;
  }();
  return t;
}

// `frame` at every level of `kernel`, interleaved (bench_levels.h).
template <class Frame>
void time_kernel_levels(benchmark::State& state, spectral::SimdKernel kernel, Frame&& frame) {
  const auto limit = bench::limit_threads(state.range(0));
  bench::LevelTimes times(relight::detail::kernel_simd_levels(kernel));
  bench::time_levels(state, times, kernel, relight::detail::kernel_simd_level(kernel), frame, [] {});
}

void BM_CompressedFrameLevels(benchmark::State& state) {
  const relight::CompressedTransport& t = level_transport();
  const spectral::RelightMatrix matrix(t.bins, {relight::parse_light_spec("D65"), relight::parse_light_spec("F11")},
                                       {});
  const spectral::DisplayTransform display(spectral::DisplayOptions{});
  const relight::DisplayEncoder8 encoder(display);
  std::vector<std::uint8_t> rgb(3 * t.pixel_count());
  time_kernel_levels(state, spectral::SimdKernel::CompressedFrame,
              [&] { relight::relight_compressed_to_display8(t, matrix, encoder, rgb.data()); });
}

void BM_HalfToFloatLevels(benchmark::State& state) {
  const relight::CompressedTransport& t = level_transport();
  const spectral::RelightMatrix matrix(t.bins, {relight::parse_light_spec("D65"), relight::parse_light_spec("F11")},
                                       {});
  std::vector<float> xyz(3 * t.pixel_count());
  time_kernel_levels(state, spectral::SimdKernel::HalfToFloat, [&] { relight::relight_compressed_into(t, matrix, xyz.data()); });
}

BENCHMARK(BM_CompressedFrameLevels)->Arg(1)->Arg(0)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(20);
BENCHMARK(BM_HalfToFloatLevels)->Arg(1)->Arg(0)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(20);

int scene_report(const char* path) {
  const spectral::SpectralImage img = spectral::read_spectral_exr(path);
  const relight::CompressedTransport t = relight::compress_transport(img);
  std::printf("%s: %d×%d, %d bins\n", path, img.width, img.height, img.bins.size());
  for (const auto& layer : t.lights) {
    std::printf("  %s: k = %d;", layer.name.c_str(), layer.k);
    for (const auto& e : layer.errors) std::printf("  %s %.3f / %.3f", e.light.c_str(), e.percentile, e.max);
    std::printf("\n");
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 3 && std::strcmp(argv[1], "--scene") == 0) return scene_report(argv[2]);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
