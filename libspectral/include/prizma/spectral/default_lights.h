#pragma once
// The default relight of a spectral image: every light layer under the spectrum its file records for
// it (prizma:lights, default_spectrum(); D65 when none is), CIE 1931 2°, a perfect white at Y = 1,
// exposure 0. What `prizma-relight FILE -o OUT` relights with when given no options and what
// prizma-render's --preview writes (the same bytes): one relight (relight_image.h) for both. The
// spectral EXR's R, G, B preview channels are to be this relight in linear sRGB too
// (spectral_exr_writer.cpp's preview_rgb still sums its own, in double: issue 22 item 2).
#include <cstddef>
#include <string>
#include <vector>

#include "prizma/spectral/light_spectrum.h"
#include "prizma/spectral/spectral_exr.h"
#include "prizma/spectral/xyz_image.h"

namespace prizma::spectral {

struct DefaultLights {
  std::vector<std::string> names;     // per layer, the name users type ("T" for an unnamed single layer)
  std::vector<LightSpectrum> lights;  // per layer, its default light
  // Per layer, why its recorded spectrum cannot be used here ("" when it can): a csv: table left on
  // the machine that rendered the file, say. That layer's light is then an "off" placeholder
  // carrying the recorded text and the factors it was recorded with (which a spectrum given for
  // every light keeps: at_light_scale), so that the file still opens.
  std::vector<std::string> errors;

  // Whether layer l's light `now` is still its placeholder (an unusable recorded spectrum, left in place).
  bool placeholder_in_place(std::size_t l, const LightSpectrum& now) const {
    return !errors[l].empty() && now.off && now.text == lights[l].text;
  }
  // Throws InputError("<source>: prizma:lights <name>", "the recorded spectrum "…" cannot be used
  // here (<why>)<hint>") when layer l's recorded spectrum cannot be used; nothing otherwise.
  void require_usable(std::size_t l, const std::string& source, const std::string& hint) const;
};

// The default light of every layer of `image`; `source` (the file) names the records in messages.
DefaultLights default_lights(const SpectralImage& image, const std::string& source);

// XYZ of every pixel with each layer under lights.lights[l] (an unusable layer's placeholder is off)
// and the default relight options (RelightOptions{}). Throws what RelightMatrix and relight_into
// throw (a light whose weights overflow a float, a layer of the wrong size).
XyzImage default_relight(const SpectralImage& image, const DefaultLights& lights);

}  // namespace prizma::spectral
