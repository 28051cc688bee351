// One render job shared by prizma-render and prizma.render (render_job.h).
#include "prizma/render/render_job.h"

#include <filesystem>
#include <tuple>
#include <utility>

#include "prizma/render/sample_range.h"

namespace prizma::render {

RenderOverrides prepare_render(Scene& scene, const RenderJob& job) {
  apply_overrides(scene, job.given, job.input_prefix);
  auto& st = scene.settings;
  if (job.given.samples) std::tie(st.sample_begin, st.sample_end) = std::pair(job.given.samples->begin, job.given.samples->end);
  if (job.spp) st.sample_end = SampleRange::starting_at(st.sample_begin, *job.spp, job.input_prefix.empty() ? "samples" : "--spp").end;
  if (job.threads > 0) st.threads = job.threads;
  RenderOverrides recorded = job.given;
  recorded.samples = SampleRange{st.sample_begin, st.sample_end};
  return recorded;
}

void record_render(spectral::SpectralImage& image, const Scene& scene, const RenderOverrides& recorded,
                   bool scene_from_file) {
  if (scene_from_file) image.info.scene_path = std::filesystem::absolute(scene.source).lexically_normal().string();
  image.info.render_options = overrides_to_json(recorded);
}

}  // namespace prizma::render
