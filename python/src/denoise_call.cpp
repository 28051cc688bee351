// prizma._prizma.denoise (module_parts.h): the denoiser of prizma-render denoise on an image in
// memory (docs/python.md, docs/denoise.md).
#include <tbb/global_control.h>

#include <optional>
#include <string>

#include "module_parts.h"
#include "native_call.h"
#include "prizma/denoise/denoise.h"
#include "prizma/spectral/error.h"

namespace prizma::python {

py::dict denoise_image(const py::dict& image_dict, const std::string& variance, const std::string& guides,
                       int window_radius_px, int patch_radius_px, double strength, double centre_threshold_se,
                       int threads) {
  if (guides != "luminance" && guides != "features")
    throw spectral::InputError("guides", "\"" + guides + "\" is neither \"luminance\" nor \"features\"");
  denoise::DenoiseOptions options;
  if (variance == "drop") {
    options.variance = denoise::VarianceOutput::Drop;
  } else if (variance != "propagate") {
    throw spectral::InputError("variance", "\"" + variance + "\" is neither \"propagate\" nor \"drop\"");
  }
  if (threads < 0) throw spectral::InputError("threads", "must be ≥ 0 (0: all cores), got " + std::to_string(threads));
  options.window_radius_px = window_radius_px;
  options.patch_radius_px = patch_radius_px;
  options.patch_k = static_cast<float>(strength);
  options.centre_threshold_se = static_cast<float>(centre_threshold_se);
  const spectral::SpectralImage raw = image_from_dict(image_dict);
  spectral::SpectralImage clean;
  {
    const WithoutGil released;
    std::optional<tbb::global_control> limit;
    if (threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, threads);
    clean = denoise::denoise(raw, denoise::compute_weights(
                                      guides == "features" ? denoise::image_guides(raw) : denoise::luminance_guides(raw), options));
  }
  return image_to_py(std::move(clean));
}

}  // namespace prizma::python
