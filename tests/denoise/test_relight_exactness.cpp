// The denoiser's promise (docs/denoise.md, issue 23): relighting the denoised image under any spectra
// equals filtering the relit raw image with the same kernels, to float rounding (≤ 1e-6 relative),
// for 1–4 lights, an emission layer and a bispectral (fluorescent) image; and a layer's output
// depends on that layer and the kernels only.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "denoise_test_util.h"
#include "prizma/denoise/denoise.h"
#include "prizma/spectral/relight_image.h"
#include "prizma/spectral/relight_matrix.h"

namespace prizma::denoise {
namespace {

constexpr int kW = 23, kH = 17;

// A noisy image: per light a smooth spatial pattern with an edge, a spectral shape of its own and
// multiplicative noise; the last layer of `with_emission` images is an emission-like blob (bright
// inside a disc, 0 outside).
spectral::SpectralImage noisy_image(int lights, bool with_emission, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.8f, 1.2f);
  const auto bins = spectral::BinLayout::linear(400, 700, 16);
  return test::make_image(
      kW, kH, bins, lights,
      [&](int l, std::size_t p, int i) {
        const int x = static_cast<int>(p % kW), y = static_cast<int>(p / kW);
        if (with_emission && l == lights - 1) {
          const int dx = x - 15, dy = y - 8;
          return dx * dx + dy * dy < 16 ? 3.0f * u(rng) * (1.0f + 0.1f * static_cast<float>(i)) : 0.0f;
        }
        const float shape = 0.5f + 0.5f * std::sin(0.4f * static_cast<float>(i + 3 * l));
        const float space = (x < 11 ? 0.3f : 0.9f) + 0.02f * static_cast<float>(y);
        return shape * space * u(rng);
      },
      [](int, std::size_t, int) { return 0.01f; });
}

// Random light spectra, one per layer: a named illuminant or a gaussian of random centre, width and
// scale (seeded).
std::vector<spectral::LightSpectrum> random_lights(int count, std::mt19937& rng) {
  const std::vector<std::string> named = {"D65", "A", "F11", "LED-B1", "blackbody:2700K"};
  std::uniform_real_distribution<double> centre(410, 690), width(5, 80), scale(0.2, 2.0);
  std::vector<spectral::LightSpectrum> out;
  for (int l = 0; l < count; ++l) {
    const std::string spec = rng() % 2 ? named[rng() % named.size()]
                                       : "gaussian:" + std::to_string(centre(rng)) + ":" + std::to_string(width(rng));
    out.push_back(spectral::parse_light_spectrum(spec + "*" + std::to_string(scale(rng))));
  }
  return out;
}

// XYZ relit in double straight from the per-light matrices (no float path), diagonal terms only.
std::vector<double> relight_double(const spectral::SpectralImage& img, const spectral::RelightMatrix& m) {
  const int n = img.bins.size();
  std::vector<double> xyz(3 * img.pixel_count(), 0.0);
  for (std::size_t p = 0; p < img.pixel_count(); ++p)
    for (std::size_t l = 0; l < img.lights.size(); ++l)
      for (int c = 0; c < 3; ++c)
        for (int i = 0; i < n; ++i) xyz[3 * p + c] += m.light(static_cast<int>(l))(c, i) * img.lights[l].data[p * n + i];
  return xyz;
}

// Relighting the denoised image = filtering the relit image: both through the float tools, and at
// a few pixels against the kernel applied in double to the relit image.
void expect_relighting_commutes(const spectral::SpectralImage& img, std::mt19937& rng, int trials) {
  const FilterWeights w = compute_weights(image_guides(img));  // the luminance, and the image's guide layers
  const spectral::SpectralImage den = denoise(img, w);
  for (int t = 0; t < trials; ++t) {
    const spectral::RelightMatrix m(img.bins, random_lights(static_cast<int>(img.lights.size()), rng), {});
    const std::vector<float> a = spectral::relight_image(den, m).xyz;
    const std::vector<float> b = apply(w, spectral::relight_image(img, m).xyz, 3);
    ASSERT_EQ(a.size(), b.size());
    double worst = 0.0;
    for (std::size_t k = 0; k < a.size(); ++k)
      worst = std::max(worst, std::abs(static_cast<double>(a[k]) - b[k]) / (std::abs(static_cast<double>(b[k])) + 1e-30));
    EXPECT_LE(worst, 1e-6) << "trial " << t;
    if (!img.reradiation.empty()) continue;  // relight_double has the diagonal terms only
    const std::vector<double> exact = relight_double(img, m);
    const int r = w.window_radius_px(), n = 2 * r + 1;
    for (auto [x, y] : {std::pair{0, 0}, {11, 8}, {10, 3}, {kW - 1, kH - 1}}) {
      const std::vector<float> k = w.kernel(x, y);
      for (int c = 0; c < 3; ++c) {
        double s = 0.0;
        for (int o = 0; o < n * n; ++o)
          if (k[o] != 0.0f) s += k[o] * exact[3 * (static_cast<std::size_t>(y + o / n - r) * kW + (x + o % n - r)) + c];
        const double got = a[3 * (static_cast<std::size_t>(y) * kW + x) + c];
        EXPECT_LE(std::abs(got - s), 1e-6 * std::abs(s)) << "pixel " << x << "," << y << " channel " << c;
      }
    }
  }
}

TEST(RelightExactness, OneToFourLightsUnderRandomSpectra) {
  std::mt19937 rng(2023);
  for (int lights = 1; lights <= 4; ++lights) {
    SCOPED_TRACE(std::to_string(lights) + " lights");
    expect_relighting_commutes(noisy_image(lights, false, 100 + lights), rng, 6);
  }
}

TEST(RelightExactness, WithAnEmissionLayer) {
  std::mt19937 rng(7);
  expect_relighting_commutes(noisy_image(3, true, 11), rng, 6);
}

TEST(RelightExactness, WithFirstHitGuides) {
  // Exact guide layers: the kernels are regressed on them (and may have negative weights) and
  // still depend on no light, so relighting still commutes with the filter.
  spectral::SpectralImage img = noisy_image(3, false, 14);
  std::mt19937 rng(15);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (const char* name : {"hit_depth", "hit_normal_x", "hit_albedo"}) {
    spectral::GuideLayer g{name, std::vector<float>(img.pixel_count()), std::vector<float>(img.pixel_count(), 0.0f)};
    for (std::size_t p = 0; p < img.pixel_count(); ++p)
      g.value[p] = 0.05f * static_cast<float>(p % kW) + 0.1f * u(rng);  // a ramp with texture
    img.guides.push_back(std::move(g));
  }
  const FilterWeights w = compute_weights(image_guides(img));
  ASSERT_EQ(w.guide_names().size(), 4u);
  EXPECT_NE(w.kernel(10, 3), compute_weights(luminance_guides(img)).kernel(10, 3));  // the regression is in effect
  expect_relighting_commutes(img, rng, 6);
}

TEST(RelightExactness, ABispectralImage) {
  // Pairs from the three blue bins into five red ones, with values of their own per pixel and light.
  spectral::SpectralImage img = noisy_image(2, false, 12);
  for (int in = 0; in < 3; ++in)
    for (int out = 9; out < 14; ++out) img.reradiation.push_back({in, out});
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> u(0.0f, 0.05f);
  for (auto& layer : img.lights)
    for (std::size_t k = 0; k < img.pixel_count() * img.reradiation.size(); ++k) layer.reradiation.push_back(u(rng));
  expect_relighting_commutes(img, rng, 6);
}

TEST(RelightExactness, ALayersOutputDependsOnItselfAndTheKernelsOnly) {
  // With the kernels held fixed, scaling light 1 by 10 scales its output by 10 and leaves light 0's
  // output bit for bit: nothing of one light leaks into another through the filter.
  spectral::SpectralImage img = noisy_image(2, false, 14);
  const FilterWeights w = compute_weights(luminance_guides(img));
  const spectral::SpectralImage a = denoise(img, w);
  for (float& v : img.lights[1].data) v *= 10.0f;
  const spectral::SpectralImage b = denoise(img, w);
  EXPECT_EQ(a.lights[0].data, b.lights[0].data);
  for (std::size_t k = 0; k < a.lights[1].data.size(); ++k)
    ASSERT_NEAR(b.lights[1].data[k], 10.0f * a.lights[1].data[k], 1e-5f * b.lights[1].data[k] + 1e-30f) << k;
}

}  // namespace
}  // namespace prizma::denoise
