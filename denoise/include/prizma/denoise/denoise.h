#pragma once
// Applying the denoiser's kernels (filter_weights.h) to per-pixel values, and denoising a whole
// spectral image with one set of kernels (docs/denoise.md).
#include <string>
#include <vector>

#include "prizma/denoise/filter_weights.h"
#include "prizma/spectral/spectral_exr.h"

namespace prizma::denoise {

// Weights: out(p) = Σ_q W(p,q)·in(q), the filtered values. SquaredWeights: Σ_q W(p,q)²·in(q), the
// variance of the filtered value when `in` holds independent variances and W is held fixed.
enum class KernelPower { Weights, SquaredWeights };

// Filters `values`, pixel-major with `channels` values per pixel (in[p·channels + c], p = y·width + x),
// with the kernels of `weights`: out[p·channels + c] = Σ_q W(p,q)^power · in[q·channels + c].
// Parallel over tiles; the result does not depend on the thread count. Throws std::invalid_argument
// when values.size() ≠ width·height·channels or channels < 1.
std::vector<float> apply(const FilterWeights& weights, const std::vector<float>& values, int channels,
                         KernelPower power = KernelPower::Weights);

// The image with every light layer's bins, its bispectral terms and its spectral-basis coefficients
// filtered by the same kernels (each tile's kernels computed once for all of them), so relighting
// the result under any spectra equals filtering the relit image with `weights`, to float rounding.
// Variance layers: propagated (Σ W²·Var) or dropped, as weights.options().variance says; the
// coefficients' measured basis errors are cleared (they described the raw values). Info is copied,
// with info.denoised = denoise_record(weights). Throws std::invalid_argument when the weights were
// made for another image size, InputError (input "image") for an image that is already denoised.
spectral::SpectralImage denoise(const spectral::SpectralImage& image, const FilterWeights& weights);

// What prizma:denoised records of a denoise with `weights` (docs/spectral-exr.md): a JSON object with
// the method, the prizma version, the guides' names, "variance" ("propagated" or "dropped") and the
// options' parameters.
std::string denoise_record(const FilterWeights& weights);

// denoise(image, compute_weights(image_guides(image), options)): the luminance and the image's guide layers.
spectral::SpectralImage denoise(const spectral::SpectralImage& image, const DenoiseOptions& options = {});

}  // namespace prizma::denoise
