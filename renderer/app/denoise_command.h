#pragma once
// prizma-render denoise and --denoise (denoise_command.cpp; docs/denoise.md): the options they share
// and the one call that denoises a rendered image.
#include <filesystem>
#include <string>

#include "prizma/denoise/denoise_options.h"
#include "prizma/tool/cli_support.h"
#include "prizma/spectral/spectral_exr.h"

namespace prizma::render_app {

// prizma-render denoise IN.exr -o OUT.exr [options] (argv[1] is "denoise").
int denoise_main(int argc, char** argv);

// The denoiser's options on a command line (--guides, --variance, --window, --patch, --strength,
// --centre-threshold); finish_denoise_options turns the --variance word into the option.
void add_denoise_options(CLI::App& app, prizma::denoise::DenoiseOptions& options, std::string& variance,
                         std::string& guides);
void finish_denoise_options(prizma::denoise::DenoiseOptions& options, const std::string& variance);

// The image denoised with guides from its own layers: the luminance, and with `features` its guide
// layers too (image_guides). The library's InputError for "image" is rethrown naming `input` (the
// file, or the render's output).
spectral::SpectralImage denoise_image(const spectral::SpectralImage& raw, const std::string& input,
                                      const prizma::denoise::DenoiseOptions& options, bool features);

// One line on what the output's variance layers hold.
std::string variance_note(const prizma::denoise::DenoiseOptions& options);

// prizma-render SCENE [--features] [--denoise [--keep-raw FILE]] (docs/denoise.md, "Using it").
void add_render_denoise_options(CLI::App& app, bool& features, bool& denoise, std::string& keep_raw);
// Refused before any work (InputError): --keep-raw without --denoise; --denoise on a shard (--samples:
// shards are merged, then denoised); with --resume, no -o or -o naming the resumed file (the raw
// samples it continues would be lost: --keep-raw may name it).
void check_render_denoise(bool denoise, const std::string& keep_raw, bool shard, const std::string& resume,
                          const std::string& output);
// The render denoised with the default options (and its guide layers with `features`) after its
// last pass; unless quiet, says so on stderr.
spectral::SpectralImage denoise_render(const spectral::SpectralImage& raw, const std::string& output, bool quiet,
                                       bool features);

// The raw render kept beside the denoised one (--keep-raw), written in the same output group.
struct RawCopy {
  const spectral::SpectralImage* image = nullptr;
  std::filesystem::path path;
};

}  // namespace prizma::render_app
