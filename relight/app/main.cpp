// prizma-relight: relights a spectral EXR under any light spectra, in milliseconds, with no re-render.
// Thin over prizma::relight: parse options, validate, run a single image, a batch or a session.
#include <tbb/global_control.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <clocale>
#include <cstdio>
#include <cmath>
#include <sstream>
#include <iostream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "prizma/relight/batch_file.h"
#include "prizma/relight/compressed_relight.h"
#include "prizma/relight/interactive_shell.h"
#include "prizma/spectral/output_image.h"
#include "prizma/relight/relight_session.h"
#include "prizma/relight/terminal_image.h"
#include "prizma/relight/serve.h"
#include "prizma/relight/terminal_preview.h"
#include "prizma/spectral/atomic_file.h"
#include "prizma/tool/cli_support.h"
#include "prizma/spectral/colour_matching.h"
#include "prizma/spectral/data_path.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/input_file.h"
#include "prizma/spectral/stderr_capture.h"
#include "prizma/tool/tool_main.h"

PRIZMA_TOOL_STARTUP_GUARD("prizma-relight");

namespace {

namespace relight = prizma::relight;
namespace spectral = prizma::spectral;
namespace tool = prizma::tool;
using spectral::InputError;

struct CliOptions {
  std::string input;
  std::string output;
  std::vector<std::string> lights;
  double exposure_ev = 0.0;
  std::string cmf = "1931";
  bool adapt = false;
  bool absolute = false;
  std::string display = "sRGB";
  std::string colour_space;
  std::string ocio;
  int bit_depth = 8;
  bool display_given = false;  // --display on the command line (not the default)
  int threads = 0;
  bool quiet = false;
  std::string batch;
  bool interactive = false;
  std::string preview;
  bool show = false;
  bool show_every = false;
  bool verbose = false;
  bool serve = false;
  std::string bind = "127.0.0.1";
  int port = 0;
  std::string save_dir = ".";
  std::vector<std::string> serve_options_given;  // --bind, --port, --save-dir on the command line
  bool no_verify = false;
  bool exact = false;
};

const char* cmf_table(spectral::Observer obs) {
  switch (obs) {
    case spectral::Observer::Cie1931_2deg: return "spectra/cie1931_xyz2deg_1nm.csv";
    case spectral::Observer::Cie1964_10deg: return "spectra/cie1964_xyz10deg_1nm.csv";
    case spectral::Observer::Cie2012_2deg: return "spectra/cie2012_xyz2deg_1nm.csv";
    case spectral::Observer::Cie2012_10deg: return "spectra/cie2012_xyz10deg_1nm.csv";
  }
  return "";
}

// The settings as the command line names them in errors.
const relight::RelightSettingNames kCliNames{"--exposure", "--bit-depth"};

// The command line's settings on top of the file's default lights.
relight::RelightSettings settings_from(const CliOptions& o, const relight::RelightSession& session) {
  relight::RelightSettings s = session.settings();
  // Each layer is set once: a repeated --light NAME=…, or SPEC for all layers given twice, is refused.
  std::vector<std::string> seen;
  for (const std::string& arg : o.lights) {
    const std::string target = arg.find('=') == std::string::npos ? std::string("*") : arg.substr(0, arg.find('='));
    if (std::find(seen.begin(), seen.end(), target) != seen.end()) {
      throw InputError("--light", target == "*" ? "a light for every layer is given twice"
                                                : "light \"" + target + "\" is given twice");
    }
    seen.push_back(target);
  }
  // The spectrum for every layer first (at each layer's scale: RelightSession::set_every_light),
  // then the named layers, wherever they stand on the command line.
  for (const std::string& arg : o.lights)
    if (arg.find('=') == std::string::npos) session.set_every_light(s.lights, relight::parse_light_spec(arg, {"--light", {}}));
  for (const std::string& arg : o.lights) {
    const auto eq = arg.find('=');
    if (eq != std::string::npos) {
      const std::string name = arg.substr(0, eq);
      const int l = session.light_index(name, "--light");
      s.lights[static_cast<std::size_t>(l)] = relight::parse_light_spec(arg.substr(eq + 1), {"--light " + name, {}});
    }
  }
  s.relight.exposure_ev = o.exposure_ev;
  s.relight.cmf = spectral::parse_observer(o.cmf, "--cmf");
  s.relight.adapt_to_d65 = o.adapt;
  s.relight.units = o.absolute ? spectral::LightUnits::Absolute : spectral::LightUnits::RelativeToWhite;
  s.output.display.display = o.display;
  s.output.display.colour_space = o.colour_space;
  if (!o.ocio.empty()) s.output.display.config = o.ocio;
  s.output.bit_depth = o.bit_depth;
  return s;  // validated by RelightSession::apply(…, kCliNames)
}

// session.save(), with what libpng prints on stderr (e.g. "libpng error: No IDATs written into
// file" when memory runs out) made part of the one error line, and running out of memory named.
void save_one_line(relight::RelightSession& session, const std::string& output, bool quiet,
                   spectral::OutputGroup* group) {
  spectral::StderrCapture capture;
  try {
    spectral::allocating("writing " + output, [&] { session.save(output, "--output", group); });
  } catch (const InputError& e) {
    throw InputError(e.input(), e.reason() + spectral::library_said("libpng", capture.finish(), e.what()));
  } catch (const spectral::RuntimeError& e) {
    throw spectral::RuntimeError(std::string(e.what()) + spectral::library_said("libpng", capture.finish(), e.what()));
  }
  const std::string printed = capture.finish();
  if (!printed.empty() && !quiet) std::cerr << printed << "\n";  // warnings of a successful write
}

// An option that nothing of this run would use is refused, not silently ignored: --display when
// the only output is an EXR (linear: XYZ, or --colour-space), --ocio when it is an XYZ EXR (no
// transform), --colour-space when the only output is a display-encoded PNG, TIFF or JPEG. With --batch, -i or --serve either may be used there.
void check_options_used(const CliOptions& o) {
  if (o.output.empty() || !o.batch.empty() || o.interactive || o.serve) return;
  const bool exr = spectral::output_format_for(o.output) == spectral::OutputFormat::Exr;
  if (exr && o.display_given && !o.show) {
    throw InputError("--display", "an EXR output is linear, not display-encoded (XYZ, or --colour-space NAME): "
                                  "--display applies to .png, .tif and .jpg outputs and --show");
  }
  if (exr && o.colour_space.empty() && !o.ocio.empty() && !o.show) {
    throw InputError("--ocio", "an XYZ EXR output is written as it is, through no OpenColorIO config: --ocio applies to "
                               ".png, .tif and .jpg outputs, EXR outputs with --colour-space, and --show");
  }
  if (!exr && !o.colour_space.empty()) {
    throw InputError("--colour-space", "applies to EXR outputs only (linear); " + o.output +
                                           " is display-encoded: choose its encoding with --display");
  }
}

// long on purpose: the relight batch in its order (checks, load, coefficients, relight, write together), each step a call.
int run(const CliOptions& o) {
  if (o.output.empty() && o.batch.empty() && !o.interactive && !o.show && !o.serve) {
    throw InputError("prizma-relight", "nothing to do: give -o FILE, --batch FILE, -i, --show or --serve");
  }
  if (o.show_every && !o.interactive) throw InputError("--show-every", "only with -i/--interactive");
  if (o.serve && o.interactive) throw InputError("--serve", "not with -i/--interactive");
  if (!o.serve && !o.serve_options_given.empty()) throw InputError(o.serve_options_given.front(), "only with --serve");
  if (!o.preview.empty() && !o.interactive) throw InputError("--preview", "only with -i/--interactive");
  // Cheap checks first: nothing is loaded when the output cannot be written.
  if (!o.output.empty()) spectral::check_output_path(o.output, "--output");
  if (!o.preview.empty()) spectral::check_output_path(o.preview, "--preview");
  check_options_used(o);
  if (!o.ocio.empty()) spectral::require_regular_file(o.ocio, "an OCIO config");

  spectral::ExrReadOptions read_options;
  read_options.verify_checksum = !o.no_verify;
  // Spectral-basis coefficients (prizma-relight compress) are relit when present, unless --exact; the
  // live page (--serve) then relights from them on the GPU too.
  read_options.read_coefficients = !o.exact;
  read_options.allow_compact = true;
  relight::RelightSession session = spectral::allocating("reading " + o.input, [&] {
    return relight::RelightSession(spectral::read_spectral_exr(o.input, read_options), o.input, o.exact);
  });
  // A denoised file says so wherever it is shown (docs/denoise.md, "Honesty").
  if (const std::string denoised = spectral::denoised_summary(session.image().info);
      !denoised.empty() && !o.quiet && (o.show || o.verbose || o.interactive || o.serve))
    std::cerr << "prizma-relight: " << o.input << ": " << denoised << "\n";
  const relight::RelightSettings cli_settings = settings_from(o, session);
  session.apply(cli_settings, kCliNames);
  if (!o.output.empty()) {
    spectral::check_output_options(spectral::output_format_for(o.output), session.settings().output);
  }
  if (o.verbose) {
    const auto& s = session.settings();
    std::cerr << "prizma-relight: input " << o.input << " (" << session.image().width << "×"
              << session.image().height << ", " << session.image().bins.size() << " bins "
              << session.image().bins.min_nm() << "–" << session.image().bins.max_nm() << " nm)\n"
              << "prizma-relight: data " << spectral::data_dir().string() << "\n"
              << "prizma-relight: cmf " << spectral::observer_name(s.relight.cmf) << " ("
              << (spectral::data_dir() / cmf_table(s.relight.cmf)).string() << ")\n"
              << "prizma-relight: OCIO config " << session.display().config_path().string() << ", "
              << session.display().description() << "\n";
    for (const std::string& note : session.image().info.notes) std::cerr << "prizma-relight: note: " << note << "\n";
    const std::string coverage =
        spectral::cmf_coverage_note(spectral::ColorMatching::get(s.relight.cmf), session.image().bins);
    if (!coverage.empty()) std::cerr << "prizma-relight: note: " << coverage << "\n";
    if (const relight::CompressedTransport* c = session.coefficients()) {
      std::string ks;
      for (const auto& layer : c->lights) ks += (ks.empty() ? "" : ", ") + layer.name + " k = " + std::to_string(layer.k);
      std::cerr << "prizma-relight: relighting from spectral-basis coefficients (" << ks
                << (session.image().compact() ? "; compact file, no bins" : "; --exact uses the bins") << ")\n";
    }
    std::istringstream lights(session.describe_lights());
    for (std::string line; std::getline(lights, line);) std::cerr << "prizma-relight: light " << line << "\n";
  }

  std::vector<relight::BatchOutput> batch;
  if (!o.batch.empty()) batch = relight::read_batch_file(o.batch, session, session.settings());
  {  // Every output of the run is a different file (one would overwrite another).
    std::vector<std::pair<std::filesystem::path, std::string>> outputs;
    if (!o.output.empty()) outputs.emplace_back(o.output, "--output");
    if (!o.preview.empty()) outputs.emplace_back(o.preview, "--preview");
    for (std::size_t i = 0; i < batch.size(); ++i)
      outputs.emplace_back(batch[i].file, o.batch + ": outputs[" + std::to_string(i) + "].file");
    spectral::check_distinct_outputs(outputs);
  }
  // The batch's images and -o appear together or not at all (a full disk on the last leaves none).
  spectral::OutputGroup outputs;
  if (!batch.empty()) {
    relight::run_batch(session, batch, o.verbose ? &std::cerr : nullptr, &outputs);
    session.apply(cli_settings, kCliNames);
  }
  if (!o.output.empty()) {
    const double ms = spectral::allocating("relighting", [&] { return session.relight(); });
    save_one_line(session, o.output, o.quiet, &outputs);
    if (o.verbose) std::cerr << "prizma-relight: wrote " << o.output << " (relit in " << ms << " ms)\n";
  }
  outputs.commit();
  if (o.show && !o.interactive) {
    const spectral::XyzImage& img = session.xyz();
    const std::vector<float> rgb = spectral::to_display(img, session.display());
    if (::isatty(STDOUT_FILENO)) {  // sixel, kitty or half blocks, sized to the window
      relight::draw_terminal_image(std::cout, rgb, img.width, img.height,
                                   relight::detect_image_protocol(STDIN_FILENO, STDOUT_FILENO),
                                   relight::terminal_size(STDOUT_FILENO), 1);
    } else {
      relight::print_terminal_thumbnail(std::cout, rgb, img.width, img.height);
    }
  }
  if (o.serve) {
    relight::ServeOptions so;
    so.bind = o.bind;
    so.port = o.port;
    so.save_dir = o.save_dir;
    if (o.verbose) so.log = &std::cerr;
    relight::RelightServer server(session, so);
    if (!relight::is_loopback_address(o.bind) && !o.quiet) {
      std::cerr << "prizma-relight: warning: --bind " << o.bind
                << " is not a loopback address: every host that can reach it sees the page and can save files\n";
    }
    relight::serve_until_signal(server, [&] { std::cout << server.url() << std::endl; });
    if (o.verbose) std::cerr << "prizma-relight: server stopped\n";
  }
  if (o.interactive) {
    relight::InteractiveOptions io;
    io.preview = o.preview;
    io.show = o.show;
    io.show_every = o.show_every;
    std::setlocale(LC_CTYPE, "");  // libedit reads the terminal's characters in the user's encoding
    relight::run_interactive_terminal(session, io, std::cerr);
  }
  return tool::kExitOk;
}

// prizma-relight compress IN.exr -o OUT.exr [--compact] [--max-error DE]: adds spectral-basis
// coefficients to a spectral EXR (docs/relight.md, "Compressed transport").
int run_compress(const std::string& input, const std::string& output, const relight::CompressFileOptions& options,
                 bool quiet) {
  spectral::require_regular_file(input, "an OpenEXR file");  // an input: the output may not replace it
  spectral::check_output_file(output, "--output");
  std::filesystem::path out_path(output);
  if (out_path.extension() != ".exr") {
    throw InputError("--output", output + ": the compressed file is a spectral EXR: give it the extension .exr");
  }
  const relight::CompressedTransport t = spectral::allocating("compressing " + input, [&] {
    return relight::compress_spectral_exr(input, output, options);
  });
  if (!quiet) {
    for (const auto& layer : t.lights) {
      std::cout << layer.name << ": k = " << layer.k << " of " << t.bins.size() << " bins; ΔE00 p"
                << options.criterion.percentile << " / max:";
      for (const auto& e : layer.errors) {
        char buf[64];
        std::snprintf(buf, sizeof buf, " %.3f / %.3f", e.percentile, e.max);
        std::cout << "  " << e.light << buf;
      }
      std::cout << "\n";
    }
    std::cout << "wrote " << output
              << (options.compact ? " (compact: coefficients only, relightable by prizma-relight alone)" : "")
              << "\n";
  }
  return tool::kExitOk;
}

int compress_main(int argc, char** argv) {
  CLI::App app{"Adds spectral-basis coefficients to a spectral EXR (relit from them, much faster).",
               "prizma-relight compress"};
  std::string input, output;
  relight::CompressFileOptions options;
  bool no_verify = false, quiet = false;
  int threads = 0;
  app.add_option("input", input, "spectral EXR with transport bins")->required()->check(tool::non_empty_path());
  app.add_option("-o,--output", output, "the compressed spectral EXR (written atomically)")
      ->required()
      ->check(tool::non_empty_path());
  app.add_flag("--compact", options.compact,
               "drop the transport bins (and variance): the file is then relit only from the coefficients");
  app.add_option("--max-error", options.criterion.max_delta_e,
                 "CIEDE2000 bound at the 99th percentile of the pixels, per layer, under D65, A, F11 and a 20 nm blue LED")
      ->capture_default_str();
  app.add_flag("--no-verify", no_verify, "read the input even when its pixels do not match prizma:checksum");
  app.add_flag("-q,--quiet", quiet, "print nothing but errors");
  app.add_option("--threads", threads, "worker threads (0 = all cores)")->check(CLI::NonNegativeNumber);
  if (const int rc = tool::parse_command_line(app, argc, argv); rc >= 0) return rc;
  options.verify_checksum = !no_verify;
  std::optional<tbb::global_control> limit;
  if (threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, threads);
  return tool::run_tool("prizma-relight", [&] { return run_compress(input, output, options, quiet); });
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 2 && std::string_view(argv[1]) == "compress") return compress_main(argc - 1, argv + 1);
  CLI::App app{"Relights a Prizma spectral EXR under any light spectra (no re-render).", "prizma-relight"};
  CliOptions o;
  app.add_option("input", o.input, "spectral EXR written by prizma-render (or any reflective spectral EXR)")
      ->required()
      ->check(tool::non_empty_path());
  app.add_option("-o,--output", o.output,
                 "output image: .png (8/16-bit), .tif, .jpg (8-bit), .exr (linear XYZ or --colour-space)")
      ->check(tool::non_empty_path());
  app.add_option("--light", o.lights,
                 "NAME=SPEC for one light layer, or SPEC for every layer; SPEC: D65, A, F11, LED-B1, "
                 "blackbody:3200K, gaussian:550:20, box:500:560, csv:FILE, off, …*SCALE (repeatable)")
      ->allow_extra_args(false);  // one value per --light: `--light D65 in.exr` leaves in.exr the input
  app.add_option("--exposure", o.exposure_ev, "exposure in stops (EV)");
  app.add_option("--cmf", o.cmf, "colour matching functions: 1931, 1964, 2012-2, 2012-10")->capture_default_str();
  app.add_flag("--adapt", o.adapt, "Bradford chromatic adaptation from the light mix's white to D65");
  app.add_option("--display", o.display, "OCIO display for PNG/TIFF/JPEG (refused with only an EXR output)")
      ->capture_default_str();
  app.add_option("--colour-space,--color-space", o.colour_space,
                 "linear OCIO colour space for EXR output (refused with only a PNG/TIFF/JPEG output)");
  app.add_option("--ocio", o.ocio, "OpenColorIO config file (default: $OCIO, else Prizma's own)")
      ->check(tool::non_empty_path());
  app.add_flag("--absolute", o.absolute, "absolute light units (no normalisation to Y = 1 for white)");
  app.add_option("--bit-depth", o.bit_depth, "PNG/TIFF bit depth")->check(CLI::IsMember({8, 16}))->capture_default_str();
  app.add_option("--batch", o.batch, "JSON file listing outputs and their settings (docs/relight.md)")
      ->check(tool::non_empty_path());
  app.add_flag("-i,--interactive", o.interactive, "read commands from stdin (type 'help')");
  app.add_option("--preview", o.preview, "interactive: image rewritten after every change")
      ->check(tool::non_empty_path());
  app.add_flag("--show", o.show, "print a true-colour terminal thumbnail (with -i: draw the image at the start)");
  app.add_flag("--show-every", o.show_every, "interactive: draw the image after every change");
  app.add_flag("-v,--verbose", o.verbose, "echo data files, OCIO config and lights");
  app.add_flag("-q,--quiet", o.quiet, "print nothing but errors (no warnings)");
  app.add_option("--threads", o.threads, "worker threads (0 = all cores)")->check(CLI::NonNegativeNumber);
  app.add_flag("--no-verify", o.no_verify,
               "read the input even when its pixels do not match prizma:checksum (a file re-encoded by another tool)");
  app.add_flag("--exact", o.exact,
               "relight from the transport bins even when the file carries spectral-basis coefficients");
  app.add_flag("--serve", o.serve, "serve the live relighting page (prints its URL; Ctrl-C stops it)");
  app.add_option("--bind", o.bind, "--serve: address to listen on")->capture_default_str();
  app.add_option("--port", o.port, "--serve: port (0: a free one)")->check(CLI::Range(0, 65535))->capture_default_str();
  app.add_option("--save-dir", o.save_dir, "--serve: the folder the page's Save writes into")
      ->capture_default_str()
      ->check(tool::non_empty_path());
  app.set_version_flag("--version", prizma::spectral::prizma_version());
  // Examples (tests/e2e/docs/check_help.py checks that every option they use exists).
  app.footer("Examples:\n"
             "  prizma-relight cs.exr -o cs.png                      (each light as the render recorded it)\n"
             "  prizma-relight cs.exr --light side=A --light back=off --exposure 1 -o a.png\n"
             "  prizma-relight cs.exr --light F11 --display \"Display P3\" -o p3.png   (every light F11, each at its scale)\n"
             "  prizma-relight cs.exr --colour-space ACEScg -o acescg.exr\n"
             "  prizma-relight cs.exr --batch outputs.json\n"
             "  prizma-relight cs.exr -i                             (the interactive shell)\n"
             "  prizma-relight cs.exr --serve                        (the live page in a browser)\n"
             "Also: prizma-relight compress IN.exr -o OUT.exr [--compact] [--max-error DE] adds spectral-basis "
             "coefficients (prizma-relight compress --help).\n"
             "Docs: share/doc/prizma/relight.md; man prizma-relight.");
  if (const int rc = tool::parse_command_line(app, argc, argv); rc >= 0) return rc;
  o.display_given = app.count("--display") > 0;
  for (const char* name : {"--bind", "--port", "--save-dir"})
    if (app.count(name) > 0) o.serve_options_given.emplace_back(name);
  std::optional<tbb::global_control> threads;
  if (o.threads > 0) threads.emplace(tbb::global_control::max_allowed_parallelism, o.threads);
  return tool::run_tool("prizma-relight", [&] { return run(o); });
}
