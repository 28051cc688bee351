// prizma-render denoise IN.exr -o OUT.exr: the light-independent denoiser (docs/denoise.md) on a
// rendered file, written atomically beside it, recording what was done in prizma:denoised.
#include <tbb/global_control.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>

#include "denoise_command.h"
#include "prizma/denoise/denoise.h"
#include "prizma/spectral/atomic_file.h"
#include "prizma/tool/cli_support.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/input_file.h"
#include "prizma/spectral/spectral_exr.h"
#include "prizma/tool/tool_main.h"

namespace prizma::render_app {

namespace denoise = prizma::denoise;
namespace spectral = prizma::spectral;
namespace tool = prizma::tool;
using spectral::InputError;

void add_denoise_options(CLI::App& app, denoise::DenoiseOptions& o, std::string& variance, std::string& guides) {
  app.add_option("--guides", guides,
                 "what the weights compare: luminance (default), or features: also the file's guide layers "
                 "(--features; measured to help less so far: docs/denoise.md)")
      ->check(CLI::IsMember({"luminance", "features"}));
  app.add_option("--variance", variance,
                 "variance layers of the output: propagate (Σ W²·Var, the filtered values' own noise) or drop")
      ->check(CLI::IsMember({"propagate", "drop"}));
  app.add_option("--window", o.window_radius_px, "kernel radius in pixels, 1–15 (default 5: 11×11 neighbours)");
  app.add_option("--patch", o.patch_radius_px, "patch radius in pixels, 0–7 (default 3)");
  app.add_option("--strength", o.patch_k, "k of the patch distance, > 0 (default 0.45): larger averages more");
  app.add_option("--centre-threshold", o.centre_threshold_se,
                 "standard errors past which a neighbour is cut off (default 3; 0: no centre test)");
}

void finish_denoise_options(denoise::DenoiseOptions& o, const std::string& variance) {
  if (variance == "drop") o.variance = denoise::VarianceOutput::Drop;
}

spectral::SpectralImage denoise_image(const spectral::SpectralImage& raw, const std::string& input,
                                      const denoise::DenoiseOptions& options, bool features) {
  // The library names the image "image"; the user knows it by its file.
  try {
    return denoise::denoise(
        raw, denoise::compute_weights(features ? denoise::image_guides(raw) : denoise::luminance_guides(raw), options));
  } catch (const InputError& e) {
    if (e.input() != "image") throw;
    throw InputError(input, e.reason());
  }
}

std::string variance_note(const denoise::DenoiseOptions& options) {
  return options.variance == denoise::VarianceOutput::Propagate
             ? "variance layers: Σ W²·Var, the filtered values' own noise with the weights held fixed (the "
               "filter's bias is not in it)"
             : "variance layers dropped (--variance drop)";
}

void add_render_denoise_options(CLI::App& app, bool& features, bool& denoise, std::string& keep_raw) {
  app.add_flag("--features", features,
               "also write the denoiser's guide layers (depth and fraction of the first scattering; docs/spectral-exr.md); "
               "with --denoise, the weights use them");
  app.add_flag("--denoise", denoise,
               "denoise the output after the last pass (implies --variance; docs/denoise.md); the file relights exactly");
  app.add_option("--keep-raw", keep_raw, "with --denoise: also write the raw render to this file (to resume or merge)")
      ->check(tool::non_empty_path());
}

void check_render_denoise(bool denoise, const std::string& keep_raw, bool shard, const std::string& resume,
                          const std::string& output) {
  if (!keep_raw.empty() && !denoise) throw InputError("--keep-raw", "only with --denoise");
  if (!denoise) return;
  if (shard)
    throw InputError("--denoise", "not with --samples: shards are merged, then denoised (render them with --variance, "
                                  "prizma-render merge, then prizma-render denoise)");
  std::error_code ec;
  if (!resume.empty() && (output.empty() || std::filesystem::equivalent(output, resume, ec)))
    throw InputError("--denoise", "with --resume, give -o for the denoised file: it cannot replace " + resume +
                                      ", the raw samples it continues (--keep-raw " + resume + " updates those)");
}

spectral::SpectralImage denoise_render(const spectral::SpectralImage& raw, const std::string& output, bool quiet,
                                       bool features) {
  const denoise::DenoiseOptions options;
  const auto start = std::chrono::steady_clock::now();
  spectral::SpectralImage clean =
      spectral::allocating("denoising", [&] { return denoise_image(raw, output, options, features); });
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (!quiet)
    std::cerr << "prizma-render: " << spectral::denoised_summary(clean.info) << " in " << seconds << " s\n"
              << "prizma-render: " << variance_note(options) << "\n";
  return clean;
}

int denoise_main(int argc, char** argv) {
  constexpr const char* kProgram = "prizma-render";
  CLI::App app{"Denoises a spectral EXR rendered with --variance: one kernel per pixel from light-independent\n"
               "guides, the same for every bin of every light, so the output relights exactly (docs/denoise.md).",
               std::string(kProgram) + " denoise"};
  app.set_version_flag("--version", spectral::prizma_version());
  std::string input, output, variance = "propagate", guides = "luminance";
  bool no_verify = false, quiet = false;
  int threads = 0;
  denoise::DenoiseOptions options;
  app.add_option("input", input, "spectral EXR with variance layers (a render, a merged or resumed file)")
      ->required()
      ->check(tool::non_empty_path());
  app.add_option("-o,--output", output, "denoised spectral EXR (never the input)")
      ->required()
      ->check(tool::non_empty_path());
  add_denoise_options(app, options, variance, guides);
  app.add_flag("--no-verify", no_verify,
               "read the input even when its pixels do not match prizma:checksum (docs/spectral-exr.md)");
  app.add_option("--threads", threads, "worker threads (0 = all cores)")->check(CLI::NonNegativeNumber);
  app.add_flag("-q,--quiet", quiet, "print nothing but errors");
  app.footer("Example:\n  prizma-render scene.json --variance --spp 64 -o raw.exr && prizma-render denoise raw.exr -o clean.exr");
  if (const int rc = tool::parse_command_line(app, argc - 1, argv + 1); rc >= 0) return rc;
  finish_denoise_options(options, variance);
  std::optional<tbb::global_control> thread_limit;
  if (threads > 0) thread_limit.emplace(tbb::global_control::max_allowed_parallelism, threads);
  return tool::run_tool(kProgram, [&] {
    // The input is recorded first, so that -o naming it (by any path) is refused before any work.
    spectral::require_regular_file(input, "an OpenEXR file");
    spectral::check_output_file(output, "-o");
    if (std::filesystem::path(output).extension() != ".exr")
      throw InputError("-o", output + ": the denoised file is a spectral EXR: give it the extension .exr");
    spectral::ExrReadOptions read_options;
    read_options.verify_checksum = !no_verify;
    read_options.read_coefficients = true;  // filtered with the same kernels, so they stay the bins' basis
    const auto start = std::chrono::steady_clock::now();
    const spectral::SpectralImage raw =
        spectral::allocating("reading " + input, [&] { return spectral::read_spectral_exr(input, read_options); });
    const spectral::SpectralImage clean =
        spectral::allocating("denoising " + input, [&] { return denoise_image(raw, input, options, guides == "features"); });
    spectral::ExrWriteOptions write_options;
    write_options.threads = threads;
    spectral::write_spectral_exr(output, clean, write_options);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!quiet)
      std::cerr << kProgram << ": " << spectral::denoised_summary(clean.info) << " (" << clean.width << "×"
                << clean.height << ", " << clean.lights.size() << (clean.lights.size() == 1 ? " light" : " lights")
                << ", " << clean.bins.size() << " bins) in " << seconds << " s → " << output << "\n"
                << kProgram << ": " << variance_note(options) << "\n";
    return tool::kExitOk;
  });
}

}  // namespace prizma::render_app
