#include "prizma/spectral/default_lights.h"

#include "prizma/spectral/error.h"
#include "prizma/spectral/light_record.h"
#include "prizma/spectral/relight_image.h"
#include "prizma/spectral/relight_matrix.h"

namespace prizma::spectral {

DefaultLights default_lights(const SpectralImage& image, const std::string& source) {
  DefaultLights out;
  for (const TransportLayer& layer : image.lights) {
    const std::string name = layer.name.empty() ? "T" : layer.name;
    const std::string spec = default_spectrum(image.info.light_records, layer.name, image.lights.size());
    const std::string context = source + ": prizma:lights " + name;
    out.names.push_back(name);
    try {
      out.lights.push_back(parse_light_spectrum(spec, {context, {}}));
      out.errors.emplace_back();
    } catch (const InputError& e) {
      LightSpectrum placeholder;
      placeholder.text = spec;
      placeholder.off = true;
      try {
        placeholder.scale = light_spec_scale(spec, {context, {}});
      } catch (const InputError&) {
        placeholder.scale = 1.0;
      }
      out.lights.push_back(std::move(placeholder));
      // Keep the inner input when it is not the context (the CSV's path, say).
      out.errors.push_back(e.input() == context ? e.reason() : e.what());
    }
  }
  return out;
}

void DefaultLights::require_usable(std::size_t l, const std::string& source, const std::string& hint) const {
  if (errors[l].empty()) return;
  throw InputError(source + ": prizma:lights " + names[l],
                   "the recorded spectrum \"" + lights[l].text + "\" cannot be used here (" + errors[l] + ")" + hint);
}

XyzImage default_relight(const SpectralImage& image, const DefaultLights& lights) {
  return relight_image(image, RelightMatrix(image.bins, lights.lights, RelightOptions{}));
}

}  // namespace prizma::spectral
