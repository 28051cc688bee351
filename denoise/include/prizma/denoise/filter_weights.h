#pragma once
// FilterWeights: the denoiser's per-pixel kernels, a pure function of the guides and the options
// (docs/denoise.md). The same kernels filter every bin of every light layer, so relighting the
// denoised image under any spectra equals filtering each relit image with them.
//
// The kernels are not stored: at 1024² pixels and an 11×11 window they would take 484 MB. They are
// computed tile by tile where they are applied (denoise.h) and for one pixel by kernel(); every
// pixel's kernel is the same number for number however the image is tiled or threaded.
#include <memory>
#include <string>
#include <vector>

#include "prizma/denoise/denoise_guides.h"
#include "prizma/denoise/denoise_options.h"

namespace prizma::denoise {

// A rectangle of pixels [x0, x0 + width) × [y0, y0 + height).
struct PixelRect {
  int x0 = 0;
  int y0 = 0;
  int width = 0;
  int height = 0;
  int pixel_count() const { return width * height; }
};

class FilterWeights {
 public:
  int width() const { return m_width; }
  int height() const { return m_height; }
  const DenoiseOptions& options() const { return m_options; }
  int window_radius_px() const { return m_options.window_radius_px; }
  // Number of neighbours per kernel: (2r + 1)².
  int kernel_size() const { return (2 * m_options.window_radius_px + 1) * (2 * m_options.window_radius_px + 1); }

  // The kernel of pixel (x, y): kernel_size() weights W(p, q) over the neighbours q = (x + dx, y + dy),
  // row-major in (dy, dx) ∈ [−r, r]²: index (dy + r)·(2r + 1) + dx + r. Zero for neighbours outside
  // the image, summing to 1 (to float rounding); non-negative unless the guides have exact features
  // (GuidePlane::exact), whose first-order regression may give some neighbours negative weights. Throws std::out_of_range for a
  // pixel outside the image.
  std::vector<float> kernel(int x, int y) const;

  // The guides the kernels are computed from, by name: "luminance", then each feature's, in order.
  std::vector<std::string> guide_names() const;

  // The kernels of every pixel of `rect` (inside the image), offset-major:
  // out[o·rect.pixel_count() + (y − y0)·rect.width + (x − x0)] is weight o of pixel (x, y), offsets
  // numbered as in kernel(). Resizes `out`. Thread-safe (const; scratch is the caller's).
  void tile_kernels(const PixelRect& rect, std::vector<float>& out) const;

 private:
  friend FilterWeights compute_weights(DenoiseGuides&&, const DenoiseOptions&);
  struct Derived;
  int m_width = 0;
  int m_height = 0;
  DenoiseOptions m_options;
  std::shared_ptr<const DenoiseGuides> m_guides;
  std::shared_ptr<const Derived> m_derived;
};

// Validates the guides (check_guides) and the options (InputError, input "denoise options", naming
// the option and its range) and returns the weights they define. The kernels themselves are
// computed when applied; with patch_k_wide, each pixel's choice between the two k is made here (one
// pass of kernels over the image, on the luminance). Depends only on its arguments, never on a light.
FilterWeights compute_weights(const DenoiseGuides& guides, const DenoiseOptions& options = {});
// The same, keeping `guides` without a copy.
FilterWeights compute_weights(DenoiseGuides&& guides, const DenoiseOptions& options = {});

}  // namespace prizma::denoise
