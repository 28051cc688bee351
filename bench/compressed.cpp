// Compressed transport at 4K: a 3840×2160, 2-light, 16-bin image to display-ready 8-bit sRGB per
// frame, exact (relight_into over the bins, as prizma-relight does) against compressed
// (relight_compressed_into over k coefficients per light), both through the same DisplayEncoder8
// (the shipped OCIO config's sRGB display, matrix applied and curve baked), interleaved in one run.
// Counters: exact_ms, compressed_ms (whole frame), their relight and encode parts, ratio =
// exact ÷ compressed, k per light, and the compressed frame's error against the exact one: ΔE00
// p99 and max over all pixels (Lab relative to the mix's white) and the 8-bit codes that differ.
// Arg: threads (0 = all).
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
#include <memory>
#include <random>
#include <string>

#include "prizma/relight/compressed_relight.h"
#include "prizma/relight/relight_image.h"
#include "prizma/spectral/colour.h"
#include "prizma/spectral/spectral_exr.h"

namespace {

using namespace prizma;

constexpr int kWidth = 3840;
constexpr int kHeight = 2160;
constexpr int kBins = 16;

// Smooth spectra that vary over the image (four Gaussian shapes mixed by smooth weights) with ±0.0005
// uniform noise: a converged render's transport, not a noisy one.
const spectral::SpectralImage& bench_image() {
  static const spectral::SpectralImage image = [] {
    spectral::SpectralImage img;
    img.width = kWidth;
    img.height = kHeight;
    img.bins = spectral::BinLayout::linear(400.0, 700.0, kBins);
    std::mt19937 rng(12345);
    std::uniform_real_distribution<float> noise(-0.0005f, 0.0005f);
    float shape[4][kBins];
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < kBins; ++i) {
        const double d = (img.bins.centre_nm(i) - (430.0 + 80.0 * j)) / 45.0;
        shape[j][i] = static_cast<float>(0.05 + std::exp(-0.5 * d * d));
      }
    for (const char* name : {"key", "back"}) {
      spectral::TransportLayer layer;
      layer.name = name;
      layer.data.resize(img.pixel_count() * kBins);
      const float phase = layer.name == "key" ? 0.0f : 1.3f;
      for (int y = 0; y < kHeight; ++y) {
        for (int x = 0; x < kWidth; ++x) {
          const float u = static_cast<float>(x) / kWidth, v = static_cast<float>(y) / kHeight;
          const float a[4] = {0.5f + 0.5f * std::sin(6.0f * u + phase), 0.5f + 0.5f * std::cos(5.0f * v + phase),
                              u * v, 0.3f * (1.0f - u)};
          float* t = layer.data.data() + (static_cast<std::size_t>(y) * kWidth + x) * kBins;
          for (int i = 0; i < kBins; ++i) {
            float s = 0.0f;
            for (int j = 0; j < 4; ++j) s += a[j] * shape[j][i];
            t[i] = std::max(0.0f, 0.5f * s + noise(rng));
          }
        }
      }
      img.lights.push_back(std::move(layer));
    }
    return img;
  }();
  return image;
}

const relight::CompressedTransport& bench_transport() {
  static const relight::CompressedTransport t = relight::compress_transport(bench_image());
  return t;
}

double percentile(std::vector<double> v, double q) {
  const std::size_t i = std::min(v.size() - 1, static_cast<std::size_t>(std::ceil(q / 100.0 * static_cast<double>(v.size()))) - 1);
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(i), v.end());
  return v[i];
}

void BM_ExactVsCompressed4K(benchmark::State& state) {
  std::unique_ptr<tbb::global_control> limit;
  if (state.range(0) > 0) {
    limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                  static_cast<std::size_t>(state.range(0)));
  }
  const spectral::SpectralImage& img = bench_image();
  const relight::CompressedTransport& comp = bench_transport();
  const std::vector<relight::LightSpec> lights = {relight::parse_light_spec("D65"), relight::parse_light_spec("F11")};
  const relight::RelightMatrix matrix(img.bins, lights, {});
  const spectral::DisplayTransform display(spectral::DisplayOptions{});
  const relight::DisplayEncoder8 encoder(display);
  std::vector<float> xyz_exact(3 * img.pixel_count()), xyz_comp(3 * img.pixel_count());
  std::vector<std::uint8_t> rgb_exact(3 * img.pixel_count()), rgb_comp(3 * img.pixel_count());
  double exact_relight = 0, exact_encode = 0, comp_relight = 0, comp_encode = 0;
  using clock = std::chrono::steady_clock;
  auto secs = [](clock::time_point a, clock::time_point b) { return std::chrono::duration<double>(b - a).count(); };
  for (auto _ : state) {
    const auto t0 = clock::now();
    relight::relight_into(img, matrix, xyz_exact.data());
    const auto t1 = clock::now();
    encoder.encode(xyz_exact.data(), img.pixel_count(), rgb_exact.data());
    const auto t2 = clock::now();
    relight::relight_compressed_into(comp, matrix, xyz_comp.data());
    const auto t3 = clock::now();
    encoder.encode(xyz_comp.data(), img.pixel_count(), rgb_comp.data());
    const auto t4 = clock::now();
    benchmark::ClobberMemory();
    exact_relight += secs(t0, t1);
    exact_encode += secs(t1, t2);
    comp_relight += secs(t2, t3);
    comp_encode += secs(t3, t4);
    state.SetIterationTime(secs(t2, t4));
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["exact_ms"] = 1e3 * (exact_relight + exact_encode) / n;
  state.counters["exact_relight_ms"] = 1e3 * exact_relight / n;
  state.counters["compressed_ms"] = 1e3 * (comp_relight + comp_encode) / n;
  state.counters["compressed_relight_ms"] = 1e3 * comp_relight / n;
  state.counters["encode_ms"] = 1e3 * (exact_encode + comp_encode) / (2 * n);
  state.counters["ratio"] = (exact_relight + exact_encode) / (comp_relight + comp_encode);
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
}

BENCHMARK(BM_ExactVsCompressed4K)->Arg(2)->Arg(1)->UseManualTime()->Unit(benchmark::kMillisecond)->MinTime(3.0);

// The one-off cost of compressing the 4K image (Gram, eigendecomposition, choice of k, projection).
void BM_Compress4K(benchmark::State& state) {
  const spectral::SpectralImage& img = bench_image();
  for (auto _ : state) benchmark::DoNotOptimize(relight::compress_transport(img));
}

BENCHMARK(BM_Compress4K)->Unit(benchmark::kMillisecond)->Iterations(1);

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
