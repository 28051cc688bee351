#pragma once
// render(): the spectral volume path tracer, from a validated Scene to a SpectralImage holding, per
// pixel, per light and per bin, the bin-averaged radiance under that light at unit white spectrum
// (docs/renderer.md). merge_shards() combines renders of disjoint sample ranges; write_preview()
// writes a render's default relight, exactly as prizma-relight writes it.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "prizma/render/scene.h"
#include "prizma/spectral/spectral_exr.h"

namespace prizma::render {

// Reported after every pass (a block of samples over the whole image).
struct RenderProgress {
  std::int64_t samples_done = 0;   // samples per pixel completed so far (in this call)
  std::int64_t samples_total = 0;  // samples per pixel this call will take if not cancelled
  std::int64_t paths = 0;          // camera paths traced so far
  double elapsed_seconds = 0.0;
};

struct RenderCallbacks {
  // Called from the calling thread between passes; may be empty.
  std::function<void(const RenderProgress&)> progress;
  // Polled at every sample: once true, render() abandons the current pass and returns the
  // completed passes: a valid image with a true, uniform sample count (info.samples,
  // info.sampleRange shortened).
  const std::atomic<bool>* cancel = nullptr;
  // Samples per pixel per pass; 0 = automatic (about 2^22 paths per pass, at least 1 sample).
  std::int64_t samples_per_pass = 0;
};

struct RenderStats {
  std::int64_t paths = 0;               // paths traced: camera samples (including rays that miss the
                                        // volume) × spectral MIS's lane groups
  std::int64_t paths_in_volume = 0;     // samples whose camera ray hit the volume's bounds
  std::int64_t collisions = 0;          // real + null collisions of free-flight sampling
  std::int64_t shadow_steps = 0;        // ratio-tracking steps of next-event estimation
  std::int64_t majorant_cells = 0;      // macrocells visited by DDA traversals
  std::int64_t nan_or_inf_count = 0;    // samples dropped because a value was not finite
  std::int64_t samples_completed = 0;   // samples per pixel in the result (sample_end' − sample_begin)
  std::int64_t pixels_converged = 0;    // pixels stopped early by target_error
  bool interrupted = false;             // the cancel flag stopped the render early
  bool wavelength_independent = false;  // the medium was traced once per path for all bins
  double wall_seconds = 0.0;
};

// Renders scene.settings' sample range of every pixel. Deterministic: a pure function of the scene,
// the seed and the sample range, independent of thread count (settings.threads: 0 = all cores).
// Throws InputError for settings it cannot render (empty bins, sample_end ≤ sample_begin, no lights).
spectral::SpectralImage render(const Scene& scene, const RenderCallbacks& callbacks = {},
                               RenderStats* stats = nullptr);
// For tests and benchmarks, never a file Prizma writes: the render with each light's default spectrum
// multiplied into its radiance at the path's own wavelengths (the light "folded into the rendering",
// as VPT does) instead of unit white; a fluorescent scene's re-radiated light lands on the diagonal.
// The reference that relighting the stored transport is checked against. The same paths as render()
// (folding draws no random numbers).
spectral::SpectralImage render_folded(const Scene& scene, const RenderCallbacks& callbacks = {},
                                      RenderStats* stats = nullptr);

// Combines renders of disjoint sample ranges of the same scene into the render of their union
// (weighted by sample counts; variance layers combined when all shards carry them). Throws
// InputError for an empty list, a denoised shard, different scene hash, seed, bins, size, lights or wavelength
// sampling, or overlapping sample ranges, naming the shard by names[k] (its file) where given, else
// "shard k". Ranges need not be contiguous; the result's sampleRange is "min:max" when they are and
// lists them ("0:8,16:24") otherwise. prizma:renderOptions: the shards' common options with the
// union as target range (empty when the shards' options differ).
spectral::SpectralImage merge_shards(const std::vector<spectral::SpectralImage>& shards,
                                     const std::vector<std::string>& names = {});

// Throws InputError(name, …) when `image` is denoised (prizma:denoised): samples cannot be added to
// filtered values (merge_shards and --resume refuse it; merge the raw renders, then denoise).
void require_raw_samples(const spectral::SpectralImage& image, const std::string& name);

// The scene's lights as the records stored in prizma:lights.
std::vector<spectral::LightRecord> light_records(const std::vector<Light>& lights);
// Lights back from an image's prizma:lights (names, directions, default spectra); lights missing
// from the records (foreign files) get the layer name, the environment direction and the default
// spectrum (spectral::default_spectrum).
std::vector<Light> lights_from_image(const spectral::SpectralImage& image);

struct PreviewOptions {
  std::string source;  // the spectral EXR the preview is of (prizma:source, messages)
  bool half = false;   // that file holds half floats: the preview relights the values rounded to half
  // The run's group of outputs the preview joins (spectral/output_group.h); null: written at once.
  spectral::OutputGroup* group = nullptr;
};

// The default relight of `image` (spectral/default_lights.h: every light under the spectrum its
// record gives, through the one relight and OpenColorIO's default display), written exactly as
// `prizma-relight SOURCE -o PATH` writes it: the same pixels, format by extension (.png, .tif, .jpg,
// .exr; spectral::write_output_image, which check_output_path checks before a render), atomically or
// into opts.group. Throws InputError for a light whose recorded spectrum cannot be used here (a csv:
// file missing on this machine), RuntimeError for I/O failures.
void write_preview(const std::filesystem::path& path, const spectral::SpectralImage& image,
                   const PreviewOptions& opts = {});

// "auto" / "spectral-tracking" / "spectral-mis" / "single", as taken by the CLI and the scene file;
// prizma:wavelengthSampling stores the resolved one (never "auto").
std::string wavelength_sampling_name(WavelengthSampling w);
WavelengthSampling parse_wavelength_sampling(std::string_view name, std::string_view input = "wavelength sampling");
// The estimator a render of `scene` runs: the setting, or for Auto the wavelength-sampling auto rule
// (docs/renderer.md, "Which scenes take spectral MIS": spectral MIS where some material's
// MaterialEvents::extinction_ratio exceeds kMisExtinctionRatio and none fluoresces). Throws
// InputError("wavelength_sampling", …) for spectral-mis with a fluorescent material.
inline constexpr double kMisExtinctionRatio = 1.1;
WavelengthSampling resolve_wavelength_sampling(const Scene& scene);
// Spectral MIS's lane groups for a render of `scene` (docs/renderer.md, "Lane groups"): 1 unless it
// runs spectral MIS over several bins; RenderSettings::mis_lane_groups when ≥ 1 (clamped to the
// bins); for auto (0) the fewest runs G of neighbouring bins (WavelengthMap::group_begin) in which
// no material's bin-average extinction varies by more than kMisGroupExtinctionRatio, and never
// runs of fewer than kMisGroupMinBins bins (G ≤ bins / kMisGroupMinBins). The ratio and the
// measurements behind it: renderer.md.
inline constexpr double kMisGroupExtinctionRatio = 2.5;
inline constexpr int kMisGroupMinBins = 3;
int resolve_mis_lane_groups(const Scene& scene);
// The lane groups a file's samples were traced with if spectral MIS traced them (what --resume
// continues with; merge_shards compares it after the estimator): prizma:misLaneGroups, and 1 where it
// is absent (a file written before lane groups: one path for all bins).
int recorded_mis_lane_groups(const spectral::SpectralExrInfo& info);

}  // namespace prizma::render
