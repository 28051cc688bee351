// prizma-render: renders a scene file to a spectral EXR (one transport layer per light), or merges
// shards rendered over disjoint sample ranges. Thin: options → Scene overrides → render() → file.
#include <tbb/global_control.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "prizma/render/render.h"
#include "prizma/render/scene.h"
#include "prizma/spectral/cli_support.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/spectral_exr.h"
#include "prizma/spectral/tool_main.h"

PRIZMA_TOOL_STARTUP_GUARD("prizma-render");

namespace {

using prizma::spectral::InputError;
namespace render = prizma::render;
namespace spectral = prizma::spectral;

constexpr const char* kProgram = "prizma-render";
constexpr int kExitInterrupted = 130;

std::atomic<bool> g_cancel{false};

extern "C" void on_sigint(int) {
  // First Ctrl-C: finish the current pass and write what is done. Second: abort, write nothing.
  if (g_cancel.exchange(true)) std::_Exit(kExitInterrupted);
}

struct Options {
  std::string scene;
  std::string output;
  std::optional<std::int64_t> spp;
  std::optional<int> width, height;
  std::string bins;
  std::optional<std::uint64_t> seed;
  // As typed: checked by the scene loader against exactly the scene field's range.
  std::optional<std::string> spp_text, width_text, height_text, seed_text;
  std::string samples;
  int threads = 0;
  std::string wavelength_sampling;
  std::optional<double> target_error;
  bool no_majorant_grid = false;
  bool variance = false;
  bool half = false;
  std::string preview;
  std::string resume;
  bool quiet = false;
  bool verbose = false;
};

// "A:B" → [A, B).
std::pair<std::int64_t, std::int64_t> parse_range(const std::string& text, const std::string& input) {
  const auto colon = text.find(':');
  try {
    if (colon == std::string::npos) throw std::invalid_argument("no colon");
    std::size_t used = 0;
    const long long a = std::stoll(text.substr(0, colon), &used);
    if (used != colon) throw std::invalid_argument("junk");
    const std::string rest = text.substr(colon + 1);
    const long long b = std::stoll(rest, &used);
    if (used != rest.size()) throw std::invalid_argument("junk");
    if (a < 0 || b <= a) throw std::invalid_argument("order");
    return {a, b};
  } catch (const std::exception&) {
    throw InputError(input, "expected A:B with 0 ≤ A < B, got \"" + text + "\"");
  }
}

// Refuses before rendering when the output's folder is missing or not writable.
void check_writable(const std::filesystem::path& path, const std::string& input) {
  std::filesystem::path dir = path.parent_path();
  if (dir.empty()) dir = ".";
  if (!std::filesystem::is_directory(dir))
    throw InputError(input, "folder " + dir.string() + " does not exist");
  if (::access(dir.c_str(), W_OK) != 0) throw InputError(input, "folder " + dir.string() + " is not writable");
}

class ProgressBar {
 public:
  explicit ProgressBar(bool enabled) : m_enabled(enabled) {}
  void update(const render::RenderProgress& p) {
    if (!m_enabled) return;
    const double frac = p.samples_total > 0 ? static_cast<double>(p.samples_done) / p.samples_total : 1.0;
    const int filled = static_cast<int>(frac * 30.0);
    const double rate = p.elapsed_seconds > 0 ? p.samples_done / p.elapsed_seconds : 0.0;
    const double eta = rate > 0 ? (p.samples_total - p.samples_done) / rate : 0.0;
    std::fprintf(stderr, "\r[%-30s] %lld/%lld spp  %.1f spp/s  %.2f Mpaths/s  ETA %.0f s ",
                 std::string(filled, '#').c_str(), static_cast<long long>(p.samples_done),
                 static_cast<long long>(p.samples_total), rate,
                 p.elapsed_seconds > 0 ? p.paths / p.elapsed_seconds * 1e-6 : 0.0, eta);
    std::fflush(stderr);
    m_drawn = true;
  }
  void finish() {
    if (m_drawn) std::fprintf(stderr, "\n");
  }

 private:
  bool m_enabled;
  bool m_drawn = false;
};

void write_outputs(const spectral::SpectralImage& image, const std::filesystem::path& output, bool half,
                   const std::string& preview, const std::vector<render::Light>& lights,
                   const std::filesystem::path& spectrum_base_dir) {
  spectral::ExrWriteOptions wo;
  wo.pixel_type = half ? spectral::ExrPixelType::Half : spectral::ExrPixelType::Float;
  spectral::write_spectral_exr(output, image, wo);
  if (!preview.empty()) {
    render::PreviewOptions po;
    po.spectrum_base_dir = spectrum_base_dir;
    render::write_preview(preview, image, lights, po);
  }
}

int merge_main(int argc, char** argv) {
  CLI::App app{"Merges prizma-render shards of disjoint sample ranges of one scene into one file.",
               std::string(kProgram) + " merge"};
  app.set_version_flag("--version", spectral::prizma_version());
  std::vector<std::string> inputs;
  std::string output, preview;
  bool half = false, quiet = false;
  app.add_option("shards", inputs, "shard files (spectral EXR written by prizma-render)")->required();
  app.add_option("-o,--output", output, "merged output file")->required();
  app.add_option("--preview", preview, "also write an sRGB preview (PNG) under the lights' default spectra");
  app.add_flag("--half", half, "write half floats");
  app.add_flag("-q,--quiet", quiet, "print nothing but errors");
  if (const int rc = spectral::parse_command_line(app, argc - 1, argv + 1); rc >= 0) return rc;
  return spectral::run_tool(kProgram, [&] {
    check_writable(output, "-o");
    std::vector<spectral::SpectralImage> shards;
    for (const auto& f : inputs) shards.push_back(spectral::read_spectral_exr(f));
    const auto merged = render::merge_shards(shards);
    write_outputs(merged, output, half, preview, render::lights_from_image(merged), {});
    if (!quiet)
      std::cerr << kProgram << ": merged " << shards.size() << " shards, samples " << merged.info.sample_range
                << " → " << output << "\n";
    return spectral::kExitOk;
  });
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 2 && std::string(argv[1]) == "merge") return merge_main(argc, argv);

  CLI::App app{"Renders a spectral volume scene to a spectral OpenEXR file: per pixel, per light and per bin\n"
               "the transport under unit white light, ready for prizma-relight.\n"
               "  prizma-render SCENE.json -o OUT.exr [options]\n"
               "  prizma-render merge a.exr b.exr ... -o all.exr",
               kProgram};
  app.set_version_flag("--version", spectral::prizma_version());
  Options o;
  app.add_option("scene", o.scene, "scene file (JSON, docs/scene-format.md)")->required();
  app.add_option("-o,--output", o.output, "output spectral EXR (default: the scene's \"output\")");
  app.add_option("--spp", o.spp_text, "samples per pixel (renders samples [begin, begin + N))");
  app.add_option("--width", o.width_text, "image width in pixels");
  app.add_option("--height", o.height_text, "image height in pixels");
  app.add_option("--bins", o.bins, "bin layout: linear:400:700:12, exp:400:700:12:1.5, edges:400,450,500");
  app.add_option("--seed", o.seed_text, "random seed");
  app.add_option("--samples", o.samples, "sample range A:B of every pixel (for shards; merge them later)");
  app.add_option("--threads", o.threads, "worker threads (0 = all cores)")->check(CLI::NonNegativeNumber);
  app.add_option("--wavelength-sampling", o.wavelength_sampling,
                 "spectral-tracking (all bins per path) or single (VPT: one wavelength per path)")
      ->check(CLI::IsMember({"spectral-tracking", "single"}));
  app.add_option("--target-error", o.target_error,
                 "stop a pixel once its relative standard error is at most this (after 16 samples)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--no-majorant-grid", o.no_majorant_grid, "one global majorant instead of the macrocell grid");
  app.add_flag("--variance", o.variance, "also write variance-of-the-mean layers");
  app.add_flag("--half", o.half, "write half floats (refused where values exceed half's range)");
  app.add_option("--preview", o.preview, "also write an sRGB preview (PNG) under the lights' default spectra");
  app.add_option("--resume", o.resume,
                 "continue a partial render: render the samples after the file's range up to the target "
                 "and merge (output defaults to this file)");
  app.add_flag("-q,--quiet", o.quiet, "no progress bar or summary");
  app.add_flag("-v,--verbose", o.verbose, "print the scene, mode and statistics");
  if (const int rc = spectral::parse_command_line(app, argc, argv); rc >= 0) return rc;

  return spectral::run_tool(kProgram, [&] {
    if (o.spp_text) o.spp = render::scene_integer_override(*o.spp_text, "samples", "--spp");
    if (o.width_text) o.width = static_cast<int>(render::scene_integer_override(*o.width_text, "camera.width", "--width"));
    if (o.height_text) o.height = static_cast<int>(render::scene_integer_override(*o.height_text, "camera.height", "--height"));
    if (o.seed_text) o.seed = render::scene_seed_override(*o.seed_text, "--seed");
    render::Scene scene =
        spectral::allocating("reading the scene and its volume", [&] { return render::load_scene(o.scene); });
    auto& st = scene.settings;
    if (o.width) scene.camera.width = *o.width;
    if (o.height) scene.camera.height = *o.height;
    if (!o.bins.empty()) st.bins = spectral::BinLayout::parse(o.bins, "--bins");
    if (o.seed) st.seed = *o.seed;
    if (!o.samples.empty()) {
      if (o.spp) throw InputError("--samples", "give either --samples or --spp");
      std::tie(st.sample_begin, st.sample_end) = parse_range(o.samples, "--samples");
    }
    if (o.spp) st.sample_end = st.sample_begin + *o.spp;
    if (o.threads > 0) st.threads = o.threads;
    if (!o.wavelength_sampling.empty())
      st.wavelength_sampling = render::parse_wavelength_sampling(o.wavelength_sampling, "--wavelength-sampling");
    if (o.target_error) st.target_error = *o.target_error;
    if (o.no_majorant_grid) st.use_majorant_grid = false;
    if (o.variance) st.write_variance = true;

    std::optional<spectral::SpectralImage> previous;
    if (!o.resume.empty()) {
      previous = spectral::read_spectral_exr(o.resume);
      const auto range = parse_range(previous->info.sample_range, o.resume + ": prizma:sampleRange");
      const std::int64_t target = o.spp ? range.first + *o.spp : st.sample_end;
      st.sample_begin = range.second;
      st.sample_end = target;
      if (st.sample_end <= st.sample_begin)
        throw InputError("--resume", o.resume + " already holds samples " + previous->info.sample_range +
                                         " (target " + std::to_string(target) + ")");
      st.write_variance = st.write_variance || !previous->lights.front().variance.empty();
    }

    std::filesystem::path output = o.output;
    if (output.empty()) output = o.resume.empty() ? scene.output : std::filesystem::path(o.resume);
    if (output.empty()) throw InputError("-o", "no output file: give -o or set \"output\" in the scene");
    check_writable(output, "-o");
    if (!o.preview.empty()) check_writable(o.preview, "--preview");

    std::optional<tbb::global_control> threads;
    if (o.threads > 0) threads.emplace(tbb::global_control::max_allowed_parallelism, o.threads);

    if (o.verbose) {
      std::cerr << kProgram << ": scene " << o.scene << " (hash " << scene.hash << "), "
                << scene.camera.width << "×" << scene.camera.height << ", " << st.bins.size() << " bins "
                << st.bins.to_string() << ", samples " << st.sample_begin << ":" << st.sample_end << ", seed "
                << st.seed << ", " << render::wavelength_sampling_name(st.wavelength_sampling)
                << (st.use_majorant_grid ? ", majorant grid" : ", global majorant") << "\n";
      for (const auto& l : scene.lights)
        std::cerr << kProgram << ": light " << l.name << " direction (" << l.direction.transpose()
                  << ") angular size " << l.angular_size_deg << "° default spectrum " << l.spectrum_spec << "\n";
    }

    std::signal(SIGINT, on_sigint);
    ProgressBar bar(!o.quiet && ::isatty(STDERR_FILENO));
    render::RenderCallbacks cb;
    cb.cancel = &g_cancel;
    cb.progress = [&](const render::RenderProgress& p) { bar.update(p); };
    render::RenderStats stats;
    spectral::SpectralImage image = spectral::allocating(
        "rendering (" + std::to_string(scene.camera.width) + "×" + std::to_string(scene.camera.height) + " pixels × " +
            std::to_string(scene.lights.size()) + " lights × " + std::to_string(st.bins.size()) + " bins)",
        [&] { return render::render(scene, cb, &stats); });
    bar.finish();
    if (previous) image = render::merge_shards({*previous, image});

    write_outputs(image, output, o.half, o.preview, scene.lights,
                  scene.source.empty() ? std::filesystem::path() : scene.source.parent_path());

    if (stats.nan_or_inf_count > 0)
      std::cerr << kProgram << ": warning: " << stats.nan_or_inf_count
                << " samples had NaN or Inf values and were counted as 0\n";
    if (!o.quiet) {
      std::cerr << kProgram << ": " << image.info.samples << " spp (" << image.info.sample_range << "), "
                << stats.paths << " paths in " << stats.wall_seconds << " s ("
                << (stats.wall_seconds > 0 ? stats.paths / stats.wall_seconds * 1e-6 : 0.0) << " Mpaths/s) → "
                << output.string() << (stats.interrupted ? " [interrupted]" : "") << "\n";
      if (o.verbose)
        std::cerr << kProgram << ": paths in volume " << stats.paths_in_volume << ", collisions "
                  << stats.collisions << ", shadow steps " << stats.shadow_steps << ", majorant cells "
                  << stats.majorant_cells << ", pixels converged " << stats.pixels_converged
                  << (stats.wavelength_independent ? ", wavelength-independent medium (one lane)" : "")
                  << "\n";
    }
    return stats.interrupted ? kExitInterrupted : spectral::kExitOk;
  });
}
