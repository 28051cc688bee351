// bench_denoise_speed: issue 23's speed goal, a 1024² image of 32 bins and 2 lights (with variance)
// denoised in ≤ 2 s on 2 cores with memory ≤ 2× the file. The image is synthetic (smooth shapes
// with edges, 5 % Gaussian noise, fixed seed): the cost depends on the size and on how many weights
// are zero, not on where the image came from. Baseline in the same run: relighting the same image
// (one streaming pass over every bin). Run on a quiet machine:
//
//   taskset -c 0,1 build/bench/bench_denoise_speed --benchmark_repetitions=5 --threads=2
//
// Counters: pixels per second; `extra_memory_x_file` = peak resident memory added by the first
// denoise (output image, guides, per-thread tile buffers) over the size of the input's pixels.
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <random>
#include <string>

#include "prizma/denoise/denoise.h"
#include "prizma/spectral/light_spectrum.h"
#include "prizma/spectral/relight_image.h"
#include "prizma/spectral/relight_matrix.h"

namespace pd = prizma::denoise;
namespace ps = prizma::spectral;

namespace {

int g_threads = 2;

const ps::SpectralImage& image() {
  static const ps::SpectralImage img = [] {
    constexpr int kSize = 1024, kBins = 32, kLights = 2;
    ps::SpectralImage im;
    im.width = im.height = kSize;
    im.bins = ps::BinLayout::linear(400, 700, kBins);
    std::mt19937 rng(1);
    std::normal_distribution<float> noise(0.0f, 0.05f);
    const std::size_t n = im.pixel_count() * kBins;
    for (int l = 0; l < kLights; ++l) {
      ps::TransportLayer layer;
      layer.name = "light" + std::to_string(l);
      layer.data.resize(n);
      layer.variance.resize(n);
      for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
          // Discs and a gradient: smooth regions with sharp edges, as a volume render has.
          const float disc = std::hypot(static_cast<float>(x % 256 - 128), static_cast<float>(y % 256 - 128)) < 80 ? 0.6f : 0.2f;
          const float base = disc + 0.3f * static_cast<float>(x) / kSize + 0.1f * static_cast<float>(l);
          for (int i = 0; i < kBins; ++i) {
            const std::size_t k = (static_cast<std::size_t>(y) * kSize + x) * kBins + i;
            const float t = base * (0.7f + 0.3f * std::sin(0.2f * static_cast<float>(i + l)));
            layer.data[k] = std::max(0.0f, t * (1.0f + noise(rng)));
            layer.variance[k] = 0.0025f * t * t;
          }
        }
      im.lights.push_back(std::move(layer));
    }
    return im;
  }();
  return img;
}

double peak_rss_bytes() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return static_cast<double>(ru.ru_maxrss) * 1024.0;
}

double pixel_bytes(const ps::SpectralImage& img) {
  double b = 0.0;
  for (const auto& l : img.lights) b += 4.0 * static_cast<double>(l.data.size() + l.variance.size());
  return b;
}

void BM_Denoise(benchmark::State& state) {
  const ps::SpectralImage& img = image();
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(g_threads));
  const double before = peak_rss_bytes();
  double extra = -1.0;
  for (auto _ : state) {
    ps::SpectralImage out = pd::denoise(img, pd::DenoiseOptions{});
    benchmark::DoNotOptimize(out.lights[0].data.data());
    if (extra < 0.0) extra = (peak_rss_bytes() - before) / pixel_bytes(img);
  }
  state.counters["pixels_per_s"] = benchmark::Counter(static_cast<double>(img.pixel_count()), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["extra_memory_x_file"] = extra;
}

// The kernels alone (every tile's, computed and dropped): the part of the cost that does not grow
// with the bins and lights.
void BM_KernelsOnly(benchmark::State& state) {
  const ps::SpectralImage& img = image();
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(g_threads));
  const pd::FilterWeights w = pd::compute_weights(pd::luminance_guides(img));
  for (auto _ : state) {
    // apply() to a one-channel plane: the kernels of every tile plus the cheapest possible use of them.
    const std::vector<float> one(img.pixel_count(), 1.0f);
    benchmark::DoNotOptimize(pd::apply(w, one, 1).data());
  }
  state.counters["pixels_per_s"] = benchmark::Counter(static_cast<double>(img.pixel_count()), benchmark::Counter::kIsIterationInvariantRate);
}

void BM_LuminanceGuides(benchmark::State& state) {
  const ps::SpectralImage& img = image();
  for (auto _ : state) benchmark::DoNotOptimize(pd::luminance_guides(img).luminance.value.data());
  state.counters["pixels_per_s"] = benchmark::Counter(static_cast<double>(img.pixel_count()), benchmark::Counter::kIsIterationInvariantRate);
}

// Baseline: relighting the same image once (a streaming pass over every bin of both lights).
void BM_RelightBaseline(benchmark::State& state) {
  const ps::SpectralImage& img = image();
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(g_threads));
  const prizma::spectral::RelightMatrix m(
      img.bins, {prizma::spectral::parse_light_spectrum("D65"), prizma::spectral::parse_light_spectrum("A")}, {});
  for (auto _ : state) benchmark::DoNotOptimize(prizma::spectral::relight_image(img, m).xyz.data());
  state.counters["pixels_per_s"] = benchmark::Counter(static_cast<double>(img.pixel_count()), benchmark::Counter::kIsIterationInvariantRate);
}

BENCHMARK(BM_Denoise)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(BM_KernelsOnly)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(BM_LuminanceGuides)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);
BENCHMARK(BM_RelightBaseline)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(3);

}  // namespace

int main(int argc, char** argv) {
  // --threads=N (default 2) before Google Benchmark's own flags.
  for (int i = 1; i < argc; ++i)
    if (std::strncmp(argv[i], "--threads=", 10) == 0) {
      g_threads = std::atoi(argv[i] + 10);
      for (int j = i; j + 1 < argc; ++j) argv[j] = argv[j + 1];
      --argc;
      break;
    }
  image();  // built before any measurement (and before the memory baseline)
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
