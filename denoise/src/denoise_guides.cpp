// The luminance guide from a spectral image's transport and variance layers, and the guides' checks.
#include "prizma/denoise/denoise_guides.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>

#include "prizma/spectral/bispectral.h"
#include "prizma/spectral/colour_matching.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/guide_names.h"
#include "prizma/spectral/light_spectrum.h"

namespace prizma::denoise {

namespace {

void check_plane(const GuidePlane& p, std::size_t pixels, bool variance_required) {
  const std::string input = "denoise guide \"" + p.name + "\"";
  if (p.value.size() != pixels)
    throw spectral::InputError(input, std::to_string(p.value.size()) + " values for " + std::to_string(pixels) +
                                          " pixels");
  if (p.variance.empty() && variance_required)
    throw spectral::InputError(input, "no variance plane (the weights compare values against their noise)");
  if (!p.variance.empty() && p.variance.size() != pixels)
    throw spectral::InputError(input, std::to_string(p.variance.size()) + " variances for " +
                                          std::to_string(pixels) + " pixels");
  for (std::size_t i = 0; i < pixels; ++i) {
    if (!std::isfinite(p.value[i]))
      throw spectral::InputError(input, "value " + std::to_string(p.value[i]) + " at pixel " + std::to_string(i));
    if (!p.variance.empty() && !(std::isfinite(p.variance[i]) && p.variance[i] >= 0.0f))
      throw spectral::InputError(input, "variance " + std::to_string(p.variance[i]) + " at pixel " + std::to_string(i));
  }
}

}  // namespace

void check_guides(const DenoiseGuides& g) {
  if (g.width < 1 || g.height < 1)
    throw spectral::InputError("denoise guides", "image size " + std::to_string(g.width) + "×" +
                                                     std::to_string(g.height) + " is empty");
  const std::size_t pixels = static_cast<std::size_t>(g.width) * static_cast<std::size_t>(g.height);
  check_plane(g.luminance, pixels, true);
  for (const GuidePlane& f : g.features) check_plane(f, pixels, false);
}

void require_raw_image(const spectral::SpectralImage& image) {
  if (!image.info.denoised.empty())
    throw spectral::InputError("image", "is already denoised (" + spectral::denoised_summary(image.info) +
                                            "): denoise the raw render");
}

DenoiseGuides luminance_guides(const spectral::SpectralImage& image) {
  require_raw_image(image);
  const std::string input = "image";
  if (image.compact())
    throw spectral::InputError(input, "a compact file (spectral-basis coefficients only) has no transport bins "
                                      "or variance to compute the denoiser's guide from");
  const std::size_t pixels = image.pixel_count(), nb = static_cast<std::size_t>(image.bins.size());
  for (const spectral::TransportLayer& layer : image.lights)
    if (layer.variance.size() != pixels * nb)
      throw spectral::InputError(input, "light \"" + layer.name +
                                            "\" has no variance layer: the denoiser weighs neighbours by their "
                                            "noise (render with --variance)");
  // ȳ per bin under an equal-energy light, normalised so that a perfect white has Y = 1 per light.
  const auto& cmf = spectral::ColorMatching::get(spectral::Observer::Cie1931_2deg);
  const Eigen::VectorXd ybar =
      spectral::relight_weights(cmf, spectral::Spectrum::constant(1.0), image.bins).row(1).transpose();
  spectral::LightSpectrum white;
  white.text = "E";
  white.spectrum = spectral::Spectrum::constant(1.0);
  const std::size_t np = image.reradiation.size();
  // (A 3×0 matrix has no storage: taking its row would offset a null pointer, so only with pairs.)
  Eigen::VectorXd ypair;
  if (np > 0) ypair = spectral::reradiation_pair_xyz(image, cmf, white).row(1).transpose();

  DenoiseGuides g;
  g.width = image.width;
  g.height = image.height;
  g.luminance.name = "luminance";
  g.luminance.value.resize(pixels);
  g.luminance.variance.resize(pixels);
  // Parallel over pixels, each written once: the thread count changes no bit.
  tbb::parallel_for(std::size_t{0}, pixels, [&](std::size_t p) {
    double y = 0.0, sigma = 0.0;
    for (const spectral::TransportLayer& layer : image.lights) {
      const float* t = layer.data.data() + p * nb;
      const float* v = layer.variance.data() + p * nb;
      for (std::size_t i = 0; i < nb; ++i) {
        y += ybar[static_cast<Eigen::Index>(i)] * t[i];
        sigma += ybar[static_cast<Eigen::Index>(i)] * std::sqrt(std::max(0.0f, v[i]));
      }
      if (!layer.reradiation.empty())
        for (std::size_t q = 0; q < np; ++q) y += ypair[static_cast<Eigen::Index>(q)] * layer.reradiation[p * np + q];
    }
    g.luminance.value[p] = static_cast<float>(y);
    g.luminance.variance[p] = static_cast<float>(sigma * sigma);
  });
  check_guides(g);
  return g;
}

DenoiseGuides image_guides(const spectral::SpectralImage& image) {
  DenoiseGuides g = luminance_guides(image);
  // The first-hit layers when the file has them (the Monte Carlo depth and scatter fraction beside
  // them only cost: docs/denoise.md, "The first-hit guides"), else the Monte Carlo ones.
  const bool any_exact = std::any_of(image.guides.begin(), image.guides.end(),
                                     [](const spectral::GuideLayer& l) { return spectral::exact_guide(l.name); });
  for (const spectral::GuideLayer& layer : image.guides)
    if (!any_exact || spectral::exact_guide(layer.name))
      g.features.push_back({layer.name, layer.value, layer.variance, spectral::exact_guide(layer.name)});
  return g;
}

}  // namespace prizma::denoise
