// Applying the kernels tile by tile: each tile's kernels are computed once (FilterWeights::tile_kernels)
// and applied to every plane before the next tile, so the kernels of the whole image are never
// held at once (a tile of 32² pixels and 121 neighbours is 0.5 MB).
#include "prizma/denoise/denoise.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "kernel_simd.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/guide_names.h"
#include "prizma/spectral/large_buffer.h"
#include "prizma/spectral/version.h"

namespace prizma::denoise {

namespace {

// Applies the kernels of `weights` to every plane, tile by tile in parallel. Each output value is
// written by one tile and summed in a fixed order, so the thread count changes no bit.
void apply_planes(const FilterWeights& weights, const std::vector<detail::ApplyPlane>& planes) {
  if (planes.empty()) return;
  const int w = weights.width(), h = weights.height(), r = weights.window_radius_px();
  const int n = 2 * r + 1, k = weights.kernel_size(), tile = weights.options().tile_size_px;
  // Neighbour o = (dy + r)·n + dx + r is pixel p + dy·width + dx.
  std::vector<std::ptrdiff_t> offset_delta(static_cast<std::size_t>(k));
  for (int o = 0; o < k; ++o) offset_delta[o] = static_cast<std::ptrdiff_t>(o / n - r) * w + (o % n - r);
  const int tiles_x = (w + tile - 1) / tile, tiles_y = (h + tile - 1) / tile;
  tbb::parallel_for(tbb::blocked_range2d<int>(0, tiles_y, 1, 0, tiles_x, 1), [&](const tbb::blocked_range2d<int>& range) {
    thread_local std::vector<float> kernels;
    std::vector<std::ptrdiff_t> delta(static_cast<std::size_t>(k));
    std::vector<float> wt(static_cast<std::size_t>(k)), wt2(static_cast<std::size_t>(k));
    for (int ty = range.rows().begin(); ty != range.rows().end(); ++ty)
      for (int tx = range.cols().begin(); tx != range.cols().end(); ++tx) {
        const PixelRect rect{tx * tile, ty * tile, std::min(tile, w - tx * tile), std::min(tile, h - ty * tile)};
        weights.tile_kernels(rect, kernels);
        const std::size_t count = static_cast<std::size_t>(rect.pixel_count());
        for (int y = 0; y < rect.height; ++y)
          for (int x = 0; x < rect.width; ++x) {
            // The pixel's non-zero weights (neighbours outside the image are zero), in offset order.
            const std::size_t t = static_cast<std::size_t>(y) * rect.width + x;
            int taps = 0;
            for (int o = 0; o < k; ++o) {
              const float v = kernels[static_cast<std::size_t>(o) * count + t];
              if (v == 0.0f) continue;
              delta[taps] = offset_delta[o];
              wt[taps] = v;
              wt2[taps] = v * v;
              ++taps;
            }
            const std::ptrdiff_t p = static_cast<std::ptrdiff_t>(rect.y0 + y) * w + rect.x0 + x;
            detail::apply_pixel(planes.data(), static_cast<int>(planes.size()), p, delta.data(), wt.data(), wt2.data(),
                                taps);
          }
      }
  });
}

}  // namespace

std::vector<float> apply(const FilterWeights& weights, const std::vector<float>& values, int channels,
                         KernelPower power) {
  const std::size_t pixels = static_cast<std::size_t>(weights.width()) * static_cast<std::size_t>(weights.height());
  if (channels < 1 || values.size() != pixels * static_cast<std::size_t>(channels))
    throw std::invalid_argument("denoise::apply: " + std::to_string(values.size()) + " values are not " +
                                std::to_string(pixels) + " pixels × " + std::to_string(channels) + " channels");
  std::vector<float> out(values.size());
  apply_planes(weights, {{values.data(), out.data(), channels, power == KernelPower::SquaredWeights}});
  return out;
}

std::string denoise_record(const FilterWeights& weights) {
  const DenoiseOptions& o = weights.options();
  const bool propagate = o.variance == VarianceOutput::Propagate;
  const std::vector<std::string> guides = weights.guide_names();
  // With first-hit guides the kernels are regressed on them (filter_weights.cpp, regress_tile).
  const bool regressed = std::any_of(guides.begin(), guides.end(), [](const std::string& g) { return spectral::exact_guide(g); });
  const nlohmann::json record = {
      {"method", regressed ? "non-local means and first-order regression" : "non-local means"},
      {"version", spectral::prizma_version()},
      {"guides", guides},
      {"variance", propagate ? "propagated" : "dropped"},
      {"parameters",
       {{"window_radius_px", o.window_radius_px},
        {"patch_radius_px", o.patch_radius_px},
        {"patch_k", o.patch_k},
        {"patch_k_wide", o.patch_k_wide},
        {"sure_radius_px", o.sure_radius_px},
        {"centre_threshold_se", o.centre_threshold_se},
        {"feature_k", o.feature_k},
        {"feature_tau", o.feature_tau}}}};
  return record.dump();
}

spectral::SpectralImage denoise(const spectral::SpectralImage& image, const FilterWeights& weights) {
  require_raw_image(image);
  if (image.width != weights.width() || image.height != weights.height())
    throw std::invalid_argument("denoise: weights for " + std::to_string(weights.width()) + "×" +
                                std::to_string(weights.height()) + " pixels applied to a " +
                                std::to_string(image.width) + "×" + std::to_string(image.height) + " image");
  const bool keep_variance = weights.options().variance == VarianceOutput::Propagate;
  spectral::SpectralImage out;
  out.width = image.width;
  out.height = image.height;
  out.bins = image.bins;
  out.info = image.info;
  out.info.denoised = denoise_record(weights);
  out.reradiation = image.reradiation;
  out.coefficient_criterion = image.coefficient_criterion;
  // Every per-pixel plane of every layer, each into its own output of the same size.
  struct Pending {
    const std::vector<float>* in;
    std::vector<float>* out;
    bool squared;
  };
  std::vector<Pending> pending;
  auto add = [&](const std::vector<float>& in, std::vector<float>& dst, bool squared) {
    if (!in.empty()) pending.push_back({&in, &dst, squared});
  };
  out.lights.resize(image.lights.size());
  for (std::size_t l = 0; l < image.lights.size(); ++l) {
    const spectral::TransportLayer& src = image.lights[l];
    spectral::TransportLayer& dst = out.lights[l];
    dst.name = src.name;
    add(src.data, dst.data, false);
    if (keep_variance) add(src.variance, dst.variance, true);
    add(src.reradiation, dst.reradiation, false);
    dst.coefficients.k = src.coefficients.k;
    dst.coefficients.basis = src.coefficients.basis;
    add(src.coefficients.values, dst.coefficients.values, false);
  }
  // The outputs are allocated (zeroed, their pages first touched) a plane per task, in huge pages
  // where offered (large_buffer.h): from one thread in 4 KB pages, this took a third of the time.
  tbb::parallel_for(std::size_t{0}, pending.size(),
                    [&](std::size_t i) { spectral::allocate_zeroed(*pending[i].out, pending[i].in->size()); });
  const std::size_t pixels = image.pixel_count();
  std::vector<detail::ApplyPlane> planes;
  for (const Pending& p : pending)
    planes.push_back({p.in->data(), p.out->data(), static_cast<int>(p.in->size() / pixels), p.squared});
  apply_planes(weights, planes);
  return out;
}

spectral::SpectralImage denoise(const spectral::SpectralImage& image, const DenoiseOptions& options) {
  return denoise(image, compute_weights(image_guides(image), options));
}

}  // namespace prizma::denoise
