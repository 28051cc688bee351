#pragma once
// One render job, options → scene → render → what the file records, shared by prizma-render
// (renderer/app/main.cpp) and prizma.render (python/src/render_call.cpp): the overrides, the sample
// range and the thread count applied to a loaded scene in one place, and the provenance a rendered
// image records (prizma:scenePath, prizma:renderOptions) in another.
#include <cstdint>
#include <optional>
#include <string>

#include "prizma/render/resume.h"
#include "prizma/render/scene.h"
#include "prizma/spectral/spectral_exr.h"

namespace prizma::render {

struct RenderJob {
  RenderOverrides given;            // the options that change what is rendered (samples: a --samples range)
  std::optional<std::int64_t> spp;  // samples per pixel from the first sample (--spp N, samples=N)
  int threads = 0;                  // worker threads; 0: the scene's setting
  // How errors name the options: "--" gives "--width", "--spp" (the command line); "" gives "width",
  // "samples" (prizma.render's arguments).
  std::string input_prefix = "--";
};

// Applies the job to a loaded scene: the overrides, the sample range (given.samples, else spp from
// the scene's first sample, else the scene's), the thread count. Returns what the output records in
// prizma:renderOptions: the given overrides with the whole sample range asked for.
RenderOverrides prepare_render(Scene& scene, const RenderJob& job);

// Records on a rendered image what it was rendered from: the scene file (absolute; none for a scene
// given as text) and the overrides (prizma:renderOptions).
void record_render(spectral::SpectralImage& image, const Scene& scene, const RenderOverrides& recorded,
                   bool scene_from_file = true);

}  // namespace prizma::render
