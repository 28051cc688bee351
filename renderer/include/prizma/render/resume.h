#pragma once
// What a render was asked for, recorded in its file so that `prizma-render --resume part.exr` needs
// nothing else (docs/distributed.md): the command-line overrides of the scene (prizma:renderOptions,
// with the target sample range) and the scene file (prizma:scenePath), checked against the scene's
// hash (prizma:sceneHash) before any sample is rendered.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "prizma/render/sample_range.h"
#include "prizma/render/scene.h"
#include "prizma/spectral/spectral_exr.h"

namespace prizma::render {

// The options of prizma-render that change what is rendered (not threads, output, preview, verbosity).
struct RenderOverrides {
  std::optional<int> width, height;
  std::optional<std::string> bins;                 // as given: "linear:400:700:12"
  std::optional<std::uint64_t> seed;
  std::optional<std::string> wavelength_sampling;  // "spectral-tracking" / "single"
  std::optional<std::string> sampler;              // "independent" / "sobol"
  std::optional<double> target_error;
  bool no_majorant_grid = false;
  bool variance = false;
  bool features = false;  // --features (guide layers); "features" in prizma:renderOptions
  bool half = false;
  // The whole sample range asked for (--samples A:B, or --spp N from the scene's first sample, or
  // the scene's "samples"); an interrupted file holds a prefix of it.
  std::optional<SampleRange> samples;

  friend bool operator==(const RenderOverrides&, const RenderOverrides&) = default;
};

// Applies the overrides (all but samples) to the scene's settings; InputError names the option as
// "<input_prefix>width" ("--width" on the command line).
void apply_overrides(Scene& scene, const RenderOverrides& o, const std::string& input_prefix = "--");

// The JSON object stored in prizma:renderOptions: only the options given, with their command-line
// names ({"width":64,"bins":"linear:400:700:4","no-majorant-grid":true,"samples":"0:64"}).
std::string overrides_to_json(const RenderOverrides& o);
// Back from prizma:renderOptions; InputError(input, …) for anything but such an object.
RenderOverrides overrides_from_json(const std::string& json, const std::string& input);

struct ResumeRequest {
  std::filesystem::path file;   // the partial render (--resume)
  std::filesystem::path scene;  // the scene given on the command line; empty: the file's prizma:scenePath
  RenderOverrides given;        // options given with --resume (samples from --samples, refused)
  std::optional<std::int64_t> spp;  // --spp N: the total number of samples, from the file's first one
  bool verify_checksum = true;      // false: --no-verify (a file another tool re-encoded; docs/spectral-exr.md)
};

struct ResumePlan {
  spectral::SpectralImage previous;  // the file as read
  Scene scene;                       // re-read, overrides applied, settings' range = the samples to add
  RenderOverrides overrides;         // as recorded, with the (new) target range
  SampleRange held;                  // what the file holds
  SampleRange target;                // what the finished file will hold
  bool complete = false;             // held == target: nothing to render
};

// Reads the file and its scene and decides what to render, before any sample is taken. Throws
// InputError when the file holds no single contiguous range, does not say which scene it is of (and
// none is given), the scene's hash differs from the recorded one, an option given contradicts the
// recorded one, or the target is smaller than what the file holds.
ResumePlan plan_resume(const ResumeRequest& request);

}  // namespace prizma::render
