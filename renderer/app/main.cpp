// prizma-render: renders a scene file to a spectral EXR (one transport layer per light), or merges
// shards rendered over disjoint sample ranges. Thin: options → Scene overrides → render() → file.
#include <signal.h>
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

#include "denoise_command.h"
#include "prizma/render/light_sampler.h"
#include "prizma/render/render.h"
#include "prizma/render/render_job.h"
#include "prizma/render/resume.h"
#include "prizma/render/sample_range.h"
#include "prizma/render/scene.h"
#include "prizma/spectral/atomic_file.h"
#include "prizma/tool/cli_support.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/input_file.h"
#include "prizma/spectral/output_group.h"
#include "prizma/spectral/output_image.h"
#include "prizma/spectral/spectral_exr.h"
#include "prizma/tool/tool_main.h"

PRIZMA_TOOL_STARTUP_GUARD("prizma-render");

namespace {

using prizma::spectral::InputError;
namespace render = prizma::render;
namespace spectral = prizma::spectral;
namespace tool = prizma::tool;

constexpr const char* kProgram = "prizma-render";

std::atomic<bool> g_cancel{false};
std::atomic<int> g_signal{0};  // the first of SIGINT, SIGTERM, SIGHUP received, or 0

// SIGINT (Ctrl-C), SIGTERM (Slurm, systemd, kill) and SIGHUP (a closed terminal) alike. The first
// lets the current pass finish and writes what is done; exit 128 + signal. A second exits at once
// with 128 + its number and writes nothing.
extern "C" void on_signal(int sig) {
  int none = 0;
  if (!g_signal.compare_exchange_strong(none, sig)) std::_Exit(128 + sig);
  g_cancel.store(true);
}

void catch_interruptions() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) ::sigaction(sig, &sa, nullptr);
}

const char* signal_name(int sig) {
  return sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : sig == SIGHUP ? "SIGHUP" : "a signal";
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
  std::string sampler;
  std::optional<double> target_error;
  bool no_majorant_grid = false;
  bool variance = false;
  bool half = false;
  std::string preview;
  std::string resume;
  bool no_verify = false;            // --no-verify: read the --resume file despite its checksum
  std::vector<std::string> defines;  // -D KEY=VALUE, in order
  bool quiet = false;
  bool verbose = false;
  bool features = false;  // --features: guide layers for the denoiser
  bool denoise = false;   // --denoise: the output is denoised after the last pass (denoise_command.h)
  std::string keep_raw;   // --keep-raw FILE: the raw render too
  std::string ocio;       // accepted only to be refused with the reason (the tools share their vocabulary)
};

// Refuses before any work outputs that cannot be written (spectral::check_output_file: a folder, a
// device, a FIFO, a missing or read-only folder, a file the run reads, …), a preview in a format that
// prizma-relight does not write, and a preview that is the same file as the output.
void check_outputs(const std::filesystem::path& output, const std::string& output_input, const std::string& preview,
                   const std::string& keep_raw = "") {
  std::vector<std::pair<std::filesystem::path, std::string>> outputs{{output, output_input}};
  if (!keep_raw.empty()) outputs.emplace_back(keep_raw, "--keep-raw");
  if (!preview.empty()) {
    spectral::check_output_path(preview, "--preview");
    outputs.emplace_back(preview, "--preview");
  }
  spectral::check_distinct_outputs(outputs);
}

class ProgressBar {
 public:
  // enabled: a bar on a terminal; lines: one line per pass instead (logs, -v without a terminal).
  ProgressBar(bool enabled, bool lines, std::int64_t first_sample)
      : m_enabled(enabled), m_lines(lines), m_first(first_sample) {}
  void update(const render::RenderProgress& p) {
    if (m_lines && !m_enabled) {
      std::fprintf(stderr, "%s: pass done: samples %lld:%lld of %lld:%lld\n", kProgram,
                   static_cast<long long>(m_first), static_cast<long long>(m_first + p.samples_done),
                   static_cast<long long>(m_first), static_cast<long long>(m_first + p.samples_total));
      std::fflush(stderr);
      return;
    }
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
  bool m_lines;
  std::int64_t m_first;
  bool m_drawn = false;
};

// The EXR and the preview appear together or not at all (a full disk on the preview leaves neither).
// With --denoise --keep-raw, `raw` is the raw render and its file, written with them.
void write_outputs(const spectral::SpectralImage& image, const std::filesystem::path& output, bool half,
                   const std::string& preview, int threads, const prizma::render_app::RawCopy& raw = {}) {
  spectral::OutputGroup outputs;
  spectral::ExrWriteOptions wo;
  wo.pixel_type = half ? spectral::ExrPixelType::Half : spectral::ExrPixelType::Float;
  wo.threads = threads;  // --threads holds for OpenEXR's encoding too
  wo.group = &outputs;
  spectral::write_spectral_exr(output, image, wo);
  if (raw.image != nullptr) spectral::write_spectral_exr(raw.path, *raw.image, wo);
  if (!preview.empty()) {
    render::PreviewOptions po;
    po.source = output.string();
    po.half = half;
    po.group = &outputs;
    render::write_preview(preview, image, po);
  }
  outputs.commit();
}

int merge_main(int argc, char** argv) {
  CLI::App app{"Merges prizma-render shards of disjoint sample ranges of one scene into one file.",
               std::string(kProgram) + " merge"};
  app.set_version_flag("--version", spectral::prizma_version());
  std::vector<std::string> inputs;
  std::string output, preview;
  bool half = false, quiet = false, verbose = false, strict = false, no_verify = false;
  int threads = 0;
  app.add_option("shards", inputs, "shard files (spectral EXR written by prizma-render)")
      ->required()
      ->check(tool::non_empty_path());
  app.add_option("-o,--output", output, "merged output file")->required()->check(tool::non_empty_path());
  app.add_option("--preview", preview,
                 "also write the default relight, as prizma-relight OUT -o PREVIEW does (.png, .tif, .jpg, .exr)")
      ->check(tool::non_empty_path());
  app.add_flag("--half", half, "write half floats");
  app.add_flag("--strict", strict, "refuse shards that leave a gap in the sample range (exit 2)");
  app.add_flag("--no-verify", no_verify,
               "read shards whose pixels do not match prizma:checksum (re-encoded by another tool: docs/spectral-exr.md)");
  app.add_flag("-q,--quiet", quiet, "print nothing but errors");
  app.add_flag("-v,--verbose", verbose, "name each shard and its samples as it is read");
  app.add_option("--threads", threads, "worker threads (0 = all cores)")->check(CLI::NonNegativeNumber);
  if (const int rc = tool::parse_command_line(app, argc - 1, argv + 1); rc >= 0) return rc;
  std::optional<tbb::global_control> thread_limit;
  if (threads > 0) thread_limit.emplace(tbb::global_control::max_allowed_parallelism, threads);
  return tool::run_tool(kProgram, [&] {
    check_outputs(output, "-o", preview);
    // Then again with the shards recorded as inputs (require_regular_file): -o or --preview naming
    // one is refused before any shard is read.
    for (const auto& f : inputs) spectral::require_regular_file(f, "an OpenEXR file");
    check_outputs(output, "-o", preview);
    std::vector<spectral::SpectralImage> shards;
    spectral::ExrReadOptions read_options;
    read_options.verify_checksum = !no_verify;
    for (const auto& f : inputs) {
      shards.push_back(spectral::read_spectral_exr(f, read_options));
      if (verbose)
        std::cerr << kProgram << ": shard " << f << ": samples " << shards.back().info.sample_range << "\n";
    }
    const auto merged = render::merge_shards(shards, inputs);
    if (merged.info.sample_range.find(',') != std::string::npos) {
      // The union has gaps: a valid render of fewer samples, but most likely a shard is missing.
      const auto held = render::parse_sample_ranges(merged.info.sample_range, "merge");
      std::string gaps;
      for (std::size_t k = 1; k < held.size(); ++k)
        gaps += (gaps.empty() ? "" : ", ") + render::SampleRange{held[k - 1].end, held[k].begin}.to_string();
      const std::string what = "the shards leave a gap in the sample range: samples " + gaps +
                               " are missing (the shards hold " + merged.info.sample_range + ")";
      if (strict) throw InputError("merge", what);
      std::cerr << kProgram << ": warning: " << what << "\n";
    }
    write_outputs(merged, output, half, preview, threads);
    if (!quiet)
      std::cerr << kProgram << ": merged " << shards.size() << (shards.size() == 1 ? " shard" : " shards")
                << ", samples " << merged.info.sample_range << " → " << output << "\n";
    return tool::kExitOk;
  });
}

// The command line's options of a render, into `o`.
void add_render_options(CLI::App& app, Options& o) {
  app.add_option("scene", o.scene, "scene file (JSON, docs/scene-format.md); with --resume, the file's own")
      ->check(tool::non_empty_path());
  app.add_option("-o,--output", o.output, "output spectral EXR (default: the scene's \"output\")")
      ->check(tool::non_empty_path());
  // --spp, --width, --height and --seed are read as text and checked as the scene's fields are (the
  // messages name the range); their value is a whole number: INT in --help.
  app.add_option("--spp", o.spp_text, "samples per pixel (renders samples [begin, begin + N); with --resume the total)")
      ->type_name("INT");
  app.add_option("--width", o.width_text, "image width in pixels")->type_name("INT");
  app.add_option("--height", o.height_text, "image height in pixels")->type_name("INT");
  app.add_option("--bins", o.bins, "bin layout: linear:400:700:12, exp:400:700:12:1.5, edges:400,450,500")
      ->type_name("SPEC");
  app.add_option("--seed", o.seed_text, "random seed")->type_name("INT");
  app.add_option("--samples", o.samples, "sample range A:B of every pixel (for shards; merge them later)")
      ->type_name("A:B");
  app.add_option("--threads", o.threads, "worker threads (0 = all cores)")->check(CLI::NonNegativeNumber);
  app.add_option("--wavelength-sampling", o.wavelength_sampling,
                 "auto (default: by the scene), spectral-tracking (all bins per path), spectral-mis (all bins, "
                 "one hero bin per path, spectral MIS) or single (VPT: one wavelength per path)")
      ->check(CLI::IsMember({"auto", "spectral-tracking", "spectral-mis", "single"}));
  app.add_option("--sampler", o.sampler,
                 "independent (PCG per sample) or sobol (the first draws of each path from a scrambled Sobol' point)")
      ->check(CLI::IsMember({"independent", "sobol"}));
  app.add_option("--target-error", o.target_error,
                 "stop a pixel once its relative standard error is at most this (after 16 samples)")
      ->check(CLI::NonNegativeNumber);
  app.add_flag("--no-majorant-grid", o.no_majorant_grid, "one global majorant instead of the macrocell grid");
  app.add_flag("--variance", o.variance, "also write variance-of-the-mean layers");
  app.add_flag("--half", o.half, "write half floats (refused where values exceed half's range)");
  prizma::render_app::add_render_denoise_options(app, o.features, o.denoise, o.keep_raw);
  app.add_option("--preview", o.preview,
                 "also write the default relight, as prizma-relight OUT -o PREVIEW does (.png, .tif, .jpg, .exr)")
      ->check(tool::non_empty_path());
  app.add_option("--resume", o.resume,
                 "continue a partial (interrupted) render from the scene and options it records, up to "
                 "its target or --spp N in all, and merge (output defaults to this file)")
      ->check(tool::non_empty_path());
  app.add_flag("--no-verify", o.no_verify,
               "with --resume: read the file even when its pixels do not match prizma:checksum (re-encoded by "
               "another tool: docs/spectral-exr.md)");
  app.add_option("-D", o.defines,
                 "KEY=VALUE: set any scene field by its path, e.g. -D camera.fov_deg=30, "
                 "-D lights.side.spectrum=A, -D materials[1].albedo=0.5 (repeatable; checked like the file)")
      ->allow_extra_args(false)
      ->type_name("KEY=VALUE");
  app.add_flag("-q,--quiet", o.quiet, "no progress bar or summary");
  app.add_flag("-v,--verbose", o.verbose, "print the scene, mode and statistics");
  app.add_option("--ocio", o.ocio, "refused: a render relights with the default config only (give --ocio to prizma-relight)")
      ->check(tool::non_empty_path());
}

// The options that change what is rendered, checked as the scene's fields are (the messages name the
// range), and the ones refused together.
render::RenderJob render_job(Options& o) {
  if (!o.ocio.empty()) {
    throw InputError("--ocio", "prizma-render takes no OpenColorIO config (the spectral EXR is not display-encoded; "
                               "--preview is the default relight, in the default config's sRGB display): give --ocio "
                               "CONFIG to prizma-relight");
  }
  if (o.spp_text) o.spp = render::scene_integer_override(*o.spp_text, "samples", "--spp");
  if (o.width_text) o.width = static_cast<int>(render::scene_integer_override(*o.width_text, "camera.width", "--width"));
  if (o.height_text) o.height = static_cast<int>(render::scene_integer_override(*o.height_text, "camera.height", "--height"));
  if (o.seed_text) o.seed = render::scene_seed_override(*o.seed_text, "--seed");
  render::RenderJob job;
  render::RenderOverrides& given = job.given;
  given.width = o.width;
  given.height = o.height;
  if (!o.bins.empty()) given.bins = o.bins;
  given.seed = o.seed;
  if (!o.wavelength_sampling.empty()) given.wavelength_sampling = o.wavelength_sampling;
  if (!o.sampler.empty()) given.sampler = o.sampler;
  given.target_error = o.target_error;
  given.no_majorant_grid = o.no_majorant_grid;
  given.variance = o.variance || o.denoise;
  given.features = o.features;
  prizma::render_app::check_render_denoise(o.denoise, o.keep_raw, !o.samples.empty(), o.resume, o.output);
  given.half = o.half;
  if (!o.samples.empty()) {
    if (o.spp) throw InputError("--samples", "give either --samples or --spp");
    given.samples = render::SampleRange::parse(o.samples, "--samples");
  }
  job.spp = o.spp;
  job.threads = o.threads;
  return job;
}

// What a run renders: the scene with the job applied, what the output records, and with --resume the
// partial file it continues.
struct Plan {
  render::Scene scene;
  render::RenderOverrides recorded;  // what the output will record in prizma:renderOptions
  std::optional<spectral::SpectralImage> previous;
};

// The scene file loaded with the job applied, or the partial file of --resume and its scene; none
// when --resume finds the file complete (then written as asked, or left alone).
std::optional<Plan> plan_render(const Options& o, const render::RenderJob& job) {
  std::vector<render::SceneOverride> defines;
  for (const std::string& d : o.defines) defines.push_back(render::parse_scene_override(d));
  Plan p;
  if (o.resume.empty()) {
    if (o.no_verify) throw InputError("--no-verify", "only with --resume (the one spectral EXR a render reads)");
    if (o.scene.empty()) throw InputError("scene", "no scene file given (or --resume a partial render)");
    p.scene = spectral::allocating("reading the scene and its volume", [&] { return render::load_scene(o.scene, defines); });
    p.recorded = render::prepare_render(p.scene, job);
    return p;
  }
  if (!defines.empty())
    throw InputError("-D", "not with --resume (the partial file's scene is continued as it was rendered)");
  render::ResumeRequest req{o.resume, o.scene, job.given, o.spp, !o.no_verify};
  render::ResumePlan plan = render::plan_resume(req);
  // In place: the output (by default the file itself) replaces it only once complete.
  spectral::allow_in_place_update(o.resume, {"-o", "--resume", "--keep-raw"});
  std::error_code ec;
  if (plan.complete && (o.output.empty() || std::filesystem::equivalent(o.output, o.resume, ec))) {
    if (!o.quiet)
      std::cerr << kProgram << ": " << o.resume << " already holds samples " << plan.held.to_string()
                << ", all that were asked for: nothing to render\n";
    return std::nullopt;
  }
  if (plan.complete) {
    check_outputs(o.output, "-o", o.preview, o.keep_raw);
    plan.previous.info.render_options = render::overrides_to_json(plan.overrides);
    const auto clean = o.denoise ? std::optional(prizma::render_app::denoise_render(plan.previous, o.output, o.quiet, o.features))
                                 : std::nullopt;
    write_outputs(clean ? *clean : plan.previous, o.output, plan.overrides.half, o.preview, o.threads,
                  {o.keep_raw.empty() ? nullptr : &plan.previous, o.keep_raw});
    return std::nullopt;
  }
  p.scene = std::move(plan.scene);
  if (o.threads > 0) p.scene.settings.threads = o.threads;
  p.recorded = plan.overrides;
  p.previous = std::move(plan.previous);
  return p;
}

// -v: the scene, the estimator and sampler, the event probabilities, the volume and the lights.
void print_scene(const render::Scene& scene) {
  const auto& st = scene.settings;
  std::cerr << kProgram << ": scene " << scene.source.string() << " (hash " << scene.hash << "), "
            << scene.camera.width << "×" << scene.camera.height << ", " << st.bins.size() << " bins "
            << st.bins.to_string() << ", samples " << st.sample_begin << ":" << st.sample_end << ", seed "
            << st.seed << ", " << render::wavelength_sampling_name(render::resolve_wavelength_sampling(scene))
            << (st.wavelength_sampling == render::WavelengthSampling::Auto ? " (auto)" : "");
  if (const int groups = render::resolve_mis_lane_groups(scene); groups > 1)
    std::cerr << " in " << groups << " lane groups" << (st.mis_lane_groups == 0 ? " (auto)" : "");
  std::cerr << ", " << render::sampler_name(st.sampler) << " sampler"
            << (st.use_majorant_grid ? ", majorant grid" : ", global majorant") << "\n";
  std::cerr << kProgram << ": event probabilities ("
            << render::event_probabilities_name(st.event_probabilities) << "): "
            << render::describe_event_probabilities(
                   render::choose_event_probabilities(st.event_probabilities, scene.medium.materials, st.bins),
                   scene.medium.materials)
            << "\n";
  if (!scene.volume_note.empty()) std::cerr << kProgram << ": " << scene.volume_note << "\n";
  for (const auto& l : scene.lights)
    std::cerr << kProgram << ": light " << l.name << ": " << render::describe_light(l) << ", default spectrum "
              << l.spectrum_spec << "\n";
}

// The run's last lines: NaN samples, and unless -q the samples, paths and speed (-v: the statistics).
void print_summary(const Options& o, const spectral::SpectralImage& image, const render::RenderStats& stats,
                   const std::filesystem::path& output) {
  if (stats.nan_or_inf_count > 0)
    std::cerr << kProgram << ": warning: " << stats.nan_or_inf_count
              << " samples had NaN or Inf values and were counted as 0\n";
  if (o.quiet) return;
  std::cerr << kProgram << ": " << image.info.samples << " spp (" << image.info.sample_range << "), "
            << stats.paths << " paths in " << stats.wall_seconds << " s ("
            << (stats.wall_seconds > 0 ? stats.paths / stats.wall_seconds * 1e-6 : 0.0) << " Mpaths/s) → "
            << output.string()
            << (stats.interrupted ? std::string(" [interrupted by ") + signal_name(g_signal.load()) + "]" : "")
            << "\n";
  if (o.verbose)
    std::cerr << kProgram << ": paths in volume " << stats.paths_in_volume << ", collisions "
              << stats.collisions << ", shadow steps " << stats.shadow_steps << ", majorant cells "
              << stats.majorant_cells << ", pixels converged " << stats.pixels_converged
              << (stats.wavelength_independent ? ", wavelength-independent medium (one lane)" : "")
              << "\n";
}

// options → scene → render → file: the render job of prizma-render.
int render_main(Options& o) {
  const render::RenderJob job = render_job(o);
  // --threads bounds the loading (classification, majorant grid) as well as the render.
  std::optional<tbb::global_control> threads;
  if (o.threads > 0) threads.emplace(tbb::global_control::max_allowed_parallelism, o.threads);
  std::optional<Plan> plan = plan_render(o, job);
  if (!plan) return tool::kExitOk;
  const render::Scene& scene = plan->scene;
  const auto& st = scene.settings;

  std::filesystem::path output = o.output;
  if (output.empty()) output = o.resume.empty() ? scene.output : std::filesystem::path(o.resume);
  if (output.empty()) throw InputError("-o", "no output file: give -o or set \"output\" in the scene");
  check_outputs(output, !o.output.empty() ? "-o" : !o.resume.empty() ? "--resume" : o.scene + ": output", o.preview,
                o.keep_raw);

  for (const std::string& w : scene.warnings) std::cerr << kProgram << ": warning: " << w << "\n";
  if (o.verbose) print_scene(scene);

  catch_interruptions();
  ProgressBar bar(!o.quiet && ::isatty(STDERR_FILENO), o.verbose, st.sample_begin);
  render::RenderCallbacks cb;
  cb.cancel = &g_cancel;
  cb.progress = [&](const render::RenderProgress& p) { bar.update(p); };
  render::RenderStats stats;
  spectral::SpectralImage image;
  try {
    image = spectral::allocating(
        "rendering (" + std::to_string(scene.camera.width) + "×" + std::to_string(scene.camera.height) +
            " pixels × " + std::to_string(scene.lights.size()) + " lights × " + std::to_string(st.bins.size()) +
            " bins)",
        [&] { return render::render(scene, cb, &stats); });
  } catch (const spectral::RuntimeError& e) {
    if (g_signal.load() == 0) throw;
    bar.finish();
    std::cerr << kProgram << ": error: " << signal_name(g_signal.load()) << ": " << e.what()
              << "; nothing written\n";
    return 128 + g_signal.load();
  }
  bar.finish();
  render::record_render(image, scene, plan->recorded);
  if (plan->previous) {
    image = render::merge_shards({*plan->previous, image}, {o.resume, "the resumed samples"});
    image.info.render_options = render::overrides_to_json(plan->recorded);  // the target, not the union
  }

  // --denoise after the last pass; an interrupted render stays raw, to be resumed.
  std::optional<spectral::SpectralImage> raw;
  if (o.denoise && !stats.interrupted) {
    raw = std::move(image);
    image = prizma::render_app::denoise_render(*raw, output.string(), o.quiet, o.features);
  } else if (o.denoise && !o.quiet) {
    std::cerr << kProgram << ": interrupted: " << output.string() << " holds the raw samples, not denoised (--resume it with -o and --denoise)\n";
  }
  write_outputs(image, output, plan->recorded.half, o.preview, o.threads,
                {raw && !o.keep_raw.empty() ? &*raw : nullptr, o.keep_raw});
  print_summary(o, image, stats, output);
  return stats.interrupted ? 128 + (g_signal.load() != 0 ? g_signal.load() : SIGINT) : tool::kExitOk;
}

}  // namespace

int inspect_main(int argc, char** argv);  // inspect.cpp

int main(int argc, char** argv) {
  if (argc >= 2 && std::string(argv[1]) == "merge") return merge_main(argc, argv);
  if (argc >= 2 && std::string(argv[1]) == "inspect") return inspect_main(argc, argv);
  if (argc >= 2 && std::string(argv[1]) == "denoise") return prizma::render_app::denoise_main(argc, argv);

  CLI::App app{"Renders a spectral volume scene to a spectral OpenEXR file: per pixel, per light and per bin\n"
               "the transport under unit white light, ready for prizma-relight.\n"
               "  prizma-render SCENE.json -o OUT.exr [options]\n"
               "  prizma-render merge a.exr b.exr ... -o all.exr\n"
               "  prizma-render inspect VOLUME|SCENE   (values, histogram, material ranges)\n"
               "  prizma-render denoise raw.exr -o clean.exr   (docs/denoise.md)",
               kProgram};
  app.set_version_flag("--version", spectral::prizma_version());
  // Examples (tests/e2e/docs/check_help.py checks that every option they use exists).
  app.footer("Examples:\n"
             "  prizma-render data/scenes/cube_sphere.json -o cs.exr --spp 64 --preview cs.png\n"
             "  prizma-render scene.json -D camera.fov_deg=30 -D lights.side.spectrum=A -o zoom.exr -q\n"
             "  prizma-render scene.json --samples 0:128 -o a.exr    (a shard; prizma-render merge a.exr b.exr -o all.exr)\n"
             "  prizma-render --resume part.exr --spp 256           (continue an interrupted render)\n"
             "  prizma-render inspect head.nii.gz                   (the values, to choose material ranges)\n"
             "  prizma-render scene.json --denoise -o clean.exr     (or: prizma-render denoise raw.exr -o clean.exr)\n"
             "Docs: share/doc/prizma/renderer.md, scene-format.md; man prizma-render.");
  Options o;
  add_render_options(app, o);
  if (const int rc = tool::parse_command_line(app, argc, argv); rc >= 0) return rc;
  return tool::run_tool(kProgram, [&] { return render_main(o); });
}
