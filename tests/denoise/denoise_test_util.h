#pragma once
// Helpers of the denoiser tests: synthetic noisy planes and spectral images with a fixed seed.
#include <cstddef>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "prizma/denoise/denoise_guides.h"
#include "prizma/spectral/spectral_exr.h"

namespace prizma::denoise::test {

// A guide whose luminance is truth(x, y) plus i.i.d. Gaussian noise of standard deviation sigma
// (seeded), with variance plane sigma².
inline DenoiseGuides noisy_guides(int width, int height, float sigma, std::uint32_t seed,
                                  const std::function<double(int, int)>& truth) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  DenoiseGuides g;
  g.width = width;
  g.height = height;
  g.luminance.name = "luminance";
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      g.luminance.value.push_back(static_cast<float>(truth(x, y) + noise(rng)));
      g.luminance.variance.push_back(sigma * sigma);
    }
  return g;
}

// A spectral image with `lights` layers named light0…, bins `bins`, values value(l, pixel, bin) and
// variances variance(l, pixel, bin).
inline spectral::SpectralImage make_image(int width, int height, const spectral::BinLayout& bins, int lights,
                                          const std::function<float(int, std::size_t, int)>& value,
                                          const std::function<float(int, std::size_t, int)>& variance) {
  spectral::SpectralImage img;
  img.width = width;
  img.height = height;
  img.bins = bins;
  const int n = bins.size();
  for (int l = 0; l < lights; ++l) {
    spectral::TransportLayer layer;
    layer.name = "light" + std::to_string(l);
    for (std::size_t p = 0; p < img.pixel_count(); ++p)
      for (int i = 0; i < n; ++i) {
        layer.data.push_back(value(l, p, i));
        layer.variance.push_back(variance(l, p, i));
      }
    img.lights.push_back(std::move(layer));
  }
  return img;
}

}  // namespace prizma::denoise::test
