#pragma once
// The synthetic transport images and the thread limit bench_relight and bench_compressed share.
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <memory>
#include <random>
#include <string>

#include "prizma/spectral/spectral_exr.h"

namespace prizma::bench {

enum class BenchSpectra {
  Uniform,  // every value uniform in [0, 1): no structure (what a memory-bound relight sees)
  Smooth,   // four Gaussian shapes mixed by smooth weights over the image, ±0.0005 noise: a converged render
};

// Two layers, "key" and "back", seed 12345.
inline spectral::SpectralImage make_bench_image(int width, int height, const spectral::BinLayout& bins,
                                                BenchSpectra kind) {
  spectral::SpectralImage img;
  img.width = width;
  img.height = height;
  img.bins = bins;
  const int n = bins.size();
  std::mt19937 rng(12345);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  std::uniform_real_distribution<float> noise(-0.0005f, 0.0005f);
  std::vector<float> shape(4 * static_cast<std::size_t>(n));
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < n; ++i) {
      const double d = (bins.centre_nm(i) - (430.0 + 80.0 * j)) / 45.0;
      shape[static_cast<std::size_t>(j * n + i)] = static_cast<float>(0.05 + std::exp(-0.5 * d * d));
    }
  for (const char* name : {"key", "back"}) {
    spectral::TransportLayer layer;
    layer.name = name;
    layer.data.resize(img.pixel_count() * static_cast<std::size_t>(n));
    if (kind == BenchSpectra::Uniform) {
      for (float& v : layer.data) v = uniform(rng);
    } else {
      const float phase = layer.name == "key" ? 0.0f : 1.3f;
      for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
          const float u = static_cast<float>(x) / static_cast<float>(width);
          const float v = static_cast<float>(y) / static_cast<float>(height);
          const float a[4] = {0.5f + 0.5f * std::sin(6.0f * u + phase), 0.5f + 0.5f * std::cos(5.0f * v + phase), u * v,
                              0.3f * (1.0f - u)};
          float* t = layer.data.data() + (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                                          static_cast<std::size_t>(x)) * static_cast<std::size_t>(n);
          for (int i = 0; i < n; ++i) {
            float s = 0.0f;
            for (int j = 0; j < 4; ++j) s += a[j] * shape[static_cast<std::size_t>(j * n + i)];
            t[i] = std::max(0.0f, 0.5f * s + noise(rng));
          }
        }
      }
    }
    img.lights.push_back(std::move(layer));
  }
  return img;
}

// A TBB thread limit for a benchmark argument (0 = all cores: none).
inline std::unique_ptr<tbb::global_control> limit_threads(std::int64_t threads) {
  if (threads <= 0) return nullptr;
  return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                               static_cast<std::size_t>(threads));
}

// The 1-minute load average (/proc/loadavg), or -1: benchmarks record the load they ran under.
inline double load_average() {
  std::ifstream in("/proc/loadavg");
  double v = -1.0;
  in >> v;
  return in ? v : -1.0;
}

}  // namespace prizma::bench
