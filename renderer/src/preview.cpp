// write_preview(): the default relight of a render, written as prizma-relight writes it.
#include "prizma/render/render.h"
#include "prizma/spectral/default_lights.h"
#include "prizma/spectral/half_float.h"
#include "prizma/spectral/output_image.h"
#include "prizma/spectral/version.h"

namespace prizma::render {

void write_preview(const std::filesystem::path& path, const spectral::SpectralImage& image, const PreviewOptions& opts) {
  const spectral::DefaultLights lights = spectral::default_lights(image, opts.source);
  for (std::size_t l = 0; l < lights.lights.size(); ++l)
    lights.require_usable(l, opts.source, "; --preview relights every light with its recorded spectrum");
  spectral::XyzImage xyz;
  if (opts.half) {
    // The values a reader of the half file gets, so that the preview is that file's relight.
    spectral::SpectralImage stored = image;
    for (spectral::TransportLayer& layer : stored.lights) {
      spectral::round_to_half(layer.data);
      spectral::round_to_half(layer.reradiation);
    }
    xyz = spectral::default_relight(stored, lights);
  } else {
    xyz = spectral::default_relight(image, lights);
  }
  const spectral::OutputOptions output;  // the default display of the OCIO config (sRGB), 8-bit
  const spectral::ImageMetadata metadata =
      spectral::relight_metadata("prizma-render " + spectral::prizma_version(), opts.source, lights.names,
                                 lights.lights, spectral::RelightOptions{}, output, image.bins);
  spectral::write_output_image(path, xyz, output, metadata, "--preview", opts.group);
}

}  // namespace prizma::render
