#pragma once
// DenoiseGuides: the light-independent per-pixel planes the denoiser's weights are computed from
// (docs/denoise.md). Nothing in them depends on the spectra a file is later relit with, so weights
// computed from them are the same for every relight, and the denoised file relights exactly.
#include <string>
#include <vector>

#include "prizma/spectral/spectral_exr.h"

namespace prizma::denoise {

// One guide plane: width·height values, row-major (value(x, y) = value[y·width + x]), and the
// variance of each value as a Monte Carlo mean (empty: the plane is noise-free).
struct GuidePlane {
  std::string name;
  std::vector<float> value;
  std::vector<float> variance;
  // True for a plane that is not a Monte Carlo estimate (the renderer's first-hit guides,
  // spectral::exact_guide): its variance is the spread within the pixel, not noise, so the weights
  // use it as it is, without filtering it first.
  bool exact = false;
};

// The guides of one image. `luminance` (with its variance) drives the patch distances; each feature
// plane adds a per-pixel test (a neighbour whose feature differs beyond its noise and the feature's
// local gradient gets a small weight). The renderer will add features such as the depth of the
// first scattering, the albedo or density there and the fraction of paths that scatter.
struct DenoiseGuides {
  int width = 0;
  int height = 0;
  GuidePlane luminance;
  std::vector<GuidePlane> features;
};

// The white-light luminance guide of a spectral image: per pixel Y = Σ_lights Σ_bins ȳ_i·T_l,i, with
// ȳ_i the CIE 1931 ȳ integrated over bin i under an equal-energy light normalised so that a perfect
// white under one light has Y = 1 (spectral::relight_weights), plus the bispectral terms' Y under
// that light (require_raw_image first). Every light layer (the emission layer too) counts. Its variance is the fully
// correlated bound (Σ_l Σ_i ȳ_i·σ_l,i)²: one path estimates every bin of every light, so the bins'
// errors are strongly positively correlated (exact when they move together; at most bins×lights
// times the true variance when they are independent). Bispectral terms carry no variance layer and
// add none. Throws InputError (input "image") when a layer has no variance layer (render with
// --variance), for a compact file (coefficients only), or for non-finite values.
DenoiseGuides luminance_guides(const spectral::SpectralImage& image);

// luminance_guides(image) with the image's guide layers (SpectralImage::guides: prizma-render
// --features) as feature planes, named after them: the guides of a rendered file. When the image
// has first-hit layers (spectral::exact_guide: "hit_…") only those, marked exact; else every layer
// (the Monte Carlo depth and scatter fraction). Throws as luminance_guides.
DenoiseGuides image_guides(const spectral::SpectralImage& image);

// Throws InputError (input "image") for an image that is already denoised (info.denoised set):
// its pixels are no longer independent means, so the noise the weights compare against is unknown.
// luminance_guides and denoise() call it first.
void require_raw_image(const spectral::SpectralImage& image);

// Checks the planes' sizes against width × height and that every value and variance is finite and
// every variance ≥ 0; the luminance must have a variance plane. Throws InputError naming the plane.
void check_guides(const DenoiseGuides& guides);

}  // namespace prizma::denoise
