// prizma-metamer: designs metamers (a reflectance that matches another under one light and differs
// under a second) and lights that hide or reveal the difference between two materials; prints the
// CIEDE2000 table under the lights involved and a standard list.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "prizma/render/scene.h"
#include "prizma/spectral/atomic_file.h"
#include "prizma/tool/cli_support.h"
#include "prizma/spectral/colour.h"
#include "prizma/spectral/colour_matching.h"
#include "prizma/spectral/data_path.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/input_file.h"
#include "prizma/spectral/light_design.h"
#include "prizma/spectral/metamer_design.h"
#include "prizma/spectral/spectrum_spec.h"
#include "prizma/tool/tool_main.h"

namespace ps = prizma::spectral;
namespace tool = prizma::tool;

namespace {

struct CommonOptions {
  std::string bins;
  std::string cmf = "1931";
  bool verbose = false;
  bool quiet = false;
  int threads = 0;
};

// -v: what the colours are computed with, on stderr.
void describe(const CommonOptions& common, const ps::ColourSetting& colour) {
  if (!common.verbose) return;
  std::fprintf(stderr, "prizma-metamer: observer %s, bins %s, data %s\n", ps::observer_name(colour.observer).c_str(),
               colour.bins.to_string().c_str(), ps::data_dir().string().c_str());
  const std::string note = ps::cmf_coverage_note(ps::ColorMatching::get(colour.observer), colour.bins);
  if (!note.empty()) std::fprintf(stderr, "prizma-metamer: note: %s\n", note.c_str());
}

struct MetamerCommand {
  std::string albedo;
  std::string match_light;
  std::string split_light;
  std::string output;
  int basis = 20;
  double min_value = 0.0;
  double max_value = 1.0;
};

struct LightCommand {
  std::string albedo_a;
  std::string albedo_b;
  std::string scene;
  std::string material_a;
  std::string material_b;
  bool hide = false;
  bool reveal = false;
  std::string reference = "D65";
  std::vector<std::string> primaries;
  std::string output;
  int basis = 40;
  double max_power_ratio = 2.0;
};

struct TabulateCommand {
  std::string spectrum;
  std::string output;
  double from_nm = 380.0;
  double to_nm = 780.0;
  double step_nm = 1.0;
};

struct WeightsCommand {
  std::string light = "D65";
  std::string output;
};

struct DeltaECommand {
  std::string light = "D65";
  std::vector<double> xyz_a;
  std::vector<double> xyz_b;
};

ps::ColourSetting colour_setting(const CommonOptions& common) {
  ps::ColourSetting colour;
  colour.observer = ps::parse_observer(common.cmf, "--cmf");
  if (!common.bins.empty()) colour.bins = ps::BinLayout::parse(common.bins, "--bins");
  describe(common, colour);
  return colour;
}

ps::Spectrum parse_option(const std::string& spec, const std::string& option) {
  return ps::parse_spectrum(spec, ps::SpecContext{option, {}});
}

// The albedo of a material of a scene file, read by the renderer's own scene reader (load_scene:
// every field checked as prizma-render checks it, csv: spectra and the volume's file included); the
// material named `material`, or the one at that index.
ps::Spectrum scene_albedo(const prizma::render::Scene& scene, const std::filesystem::path& scene_path,
                          const std::string& material) {
  const auto& materials = scene.medium.materials;
  for (std::size_t i = 0; i < materials.size(); ++i)
    if (materials[i].name == material || std::to_string(i) == material) return materials[i].albedo;
  std::string known;
  for (const auto& m : materials) known += (known.empty() ? "" : ", ") + m.name;
  throw ps::InputError(scene_path.string(), "no material \"" + material + "\"" +
                                                (known.empty() ? std::string(" (it has none)") : " (its materials: " + known + ")"));
}

void print_table(const std::vector<ps::NamedLight>& lights, const std::vector<double>& values,
                 const std::string& header) {
  std::printf("%-24s %10s\n", "light", header.c_str());
  for (size_t i = 0; i < lights.size(); ++i) std::printf("%-24s %10.3f\n", lights[i].name.c_str(), values[i]);
}

int run_metamer(const MetamerCommand& cmd, const CommonOptions& common) {
  ps::MetamerOptions options;
  options.colour = colour_setting(common);
  options.basis_size = cmd.basis;
  options.min_value = cmd.min_value;
  options.max_value = cmd.max_value;
  const ps::Spectrum albedo = parse_option(cmd.albedo, "--albedo");
  const ps::Spectrum match = parse_option(cmd.match_light, "--match-light");
  const ps::Spectrum split = parse_option(cmd.split_light, "--split-light");
  ps::check_output_file(cmd.output, "--output");  // again, now that the csv: inputs are read
  const ps::MetamerResult result = ps::design_metamer(albedo, match, split, options);
  ps::write_spectrum_csv(cmd.output, result.reflectance, "reflectance");

  std::vector<ps::NamedLight> lights{{"match " + cmd.match_light, match}, {"split " + cmd.split_light, split}};
  for (ps::NamedLight& l : ps::standard_report_lights()) lights.push_back(std::move(l));
  std::vector<double> values;
  for (const ps::NamedLight& l : lights)
    values.push_back(ps::delta_e2000_under(albedo, result.reflectance, l.spectrum, options.colour));
  if (common.quiet) return tool::kExitOk;
  std::printf("metamer of %s written to %s (values %.3f..%.3f)\n", cmd.albedo.c_str(), cmd.output.c_str(),
              result.reflectance.min_value(), result.reflectance.max_value());
  print_table(lights, values, "dE00");
  return tool::kExitOk;
}

int run_light(const LightCommand& cmd, const CommonOptions& common) {
  if (cmd.hide == cmd.reveal) throw ps::InputError("--hide/--reveal", "give exactly one of them");
  ps::LightDesignOptions options;
  options.colour = colour_setting(common);
  options.basis_size = cmd.basis;
  options.max_power_ratio = cmd.max_power_ratio;
  std::optional<prizma::render::Scene> scene;
  const auto albedo = [&](const std::string& spec, const std::string& material, const std::string& letter) {
    const std::string spec_option = "--albedo-" + letter;
    const std::string material_option = "--material-" + letter;
    if (!spec.empty() && !material.empty())
      throw ps::InputError(spec_option, "give either " + spec_option + " or " + material_option + ", not both");
    if (!material.empty()) {
      if (cmd.scene.empty()) throw ps::InputError(material_option, "needs --scene");
      if (!scene) scene = prizma::render::load_scene(cmd.scene);  // read once for both materials
      return scene_albedo(*scene, cmd.scene, material);
    }
    if (spec.empty()) throw ps::InputError(spec_option, "missing (or give --scene and " + material_option + ")");
    return parse_option(spec, spec_option);
  };
  const ps::Spectrum a = albedo(cmd.albedo_a, cmd.material_a, "a");
  const ps::Spectrum b = albedo(cmd.albedo_b, cmd.material_b, "b");
  const ps::Spectrum reference = parse_option(cmd.reference, "--reference");
  std::vector<ps::Spectrum> primaries;
  for (size_t i = 0; i < cmd.primaries.size(); ++i)
    primaries.push_back(parse_option(cmd.primaries[i], "--primaries[" + std::to_string(i) + "]"));
  ps::check_output_file(cmd.output, "--output");  // again, now that the scene and csv: inputs are read
  const ps::LightDesignResult result =
      ps::design_light(a, b, cmd.hide ? ps::LightGoal::Hide : ps::LightGoal::Reveal, reference, primaries, options);
  ps::write_spectrum_csv(cmd.output, result.light, "relative_spd");

  if (common.quiet) return tool::kExitOk;
  std::printf("%s light written to %s\n", cmd.hide ? "hiding" : "revealing", cmd.output.c_str());
  if (!primaries.empty()) {
    std::printf("mix:");
    for (size_t i = 0; i < primaries.size(); ++i) std::printf(" %s*%.6g", cmd.primaries[i].c_str(), result.weights[i]);
    std::printf("\n");
  }
  std::vector<ps::NamedLight> lights{{"designed", result.light}, {"reference " + cmd.reference, reference}};
  for (ps::NamedLight& l : ps::standard_report_lights()) lights.push_back(std::move(l));
  std::vector<double> values;
  for (const ps::NamedLight& l : lights) values.push_back(ps::delta_e2000_under(a, b, l.spectrum, options.colour));
  print_table(lights, values, "dE00");
  return tool::kExitOk;
}

int run_tabulate(const TabulateCommand& cmd) {
  if (!(cmd.step_nm > 0.0) || !(cmd.from_nm < cmd.to_nm) || (cmd.to_nm - cmd.from_nm) / cmd.step_nm > 1e6)
    throw ps::InputError("--from/--to/--step", "need from < to and a step > 0 giving at most 1e6 samples");
  const ps::Spectrum s = parse_option(cmd.spectrum, "--spectrum");
  ps::check_output_file(cmd.output, "--output");  // again, now that a csv: input is read
  std::vector<double> lambda;
  for (double l = cmd.from_nm; l < cmd.to_nm - 1e-9; l += cmd.step_nm) lambda.push_back(l);
  lambda.push_back(cmd.to_nm);
  ps::write_spectrum_csv(cmd.output, s.resampled(lambda), "value");
  return tool::kExitOk;
}

// The relighter's matrix for one light: XYZ of a pixel = Σ_bins weight · transport. Lets scripts
// predict relit colours from transport spectra without re-implementing the colour matching.
int run_weights(const WeightsCommand& cmd, const CommonOptions& common) {
  const ps::ColourSetting colour = colour_setting(common);
  const ps::Spectrum light = parse_option(cmd.light, "--light");
  ps::check_output_file(cmd.output, "--output");  // again, now that a csv: input is read
  const Eigen::Matrix<double, 3, Eigen::Dynamic> w =
      ps::relight_weights(ps::ColorMatching::get(colour.observer), light, colour.bins);
  std::string text = "lo_nm,hi_nm,X,Y,Z\n";
  for (int i = 0; i < colour.bins.size(); ++i) {
    char line[160];
    std::snprintf(line, sizeof line, "%.9g,%.9g,%.17g,%.17g,%.17g\n", colour.bins.lo_nm(i), colour.bins.hi_nm(i),
                  w(0, i), w(1, i), w(2, i));
    text += line;
  }
  ps::write_file_atomically(cmd.output, text);
  return tool::kExitOk;
}

int run_delta_e(const DeltaECommand& cmd, const CommonOptions& common) {
  const ps::ColourSetting colour = colour_setting(common);
  const ps::Spectrum light = parse_option(cmd.light, "--light");
  // The white of a relit image: a perfect white (transport 1 in every bin) under the light.
  const Eigen::Vector3d white = ps::reflectance_xyz(ps::Spectrum::constant(1.0), light, colour);
  const Eigen::Vector3d xyz_a(cmd.xyz_a[0], cmd.xyz_a[1], cmd.xyz_a[2]);
  const Eigen::Vector3d xyz_b(cmd.xyz_b[0], cmd.xyz_b[1], cmd.xyz_b[2]);
  if (!xyz_a.allFinite() || !xyz_b.allFinite()) throw ps::InputError("--xyz-a/--xyz-b", "values must be finite");
  const Eigen::Vector3d lab_a = ps::xyz_to_lab(xyz_a, white);
  const Eigen::Vector3d lab_b = ps::xyz_to_lab(xyz_b, white);
  std::printf("Lab a: %.3f %.3f %.3f\nLab b: %.3f %.3f %.3f\ndE00: %.4f\n", lab_a[0], lab_a[1], lab_a[2], lab_b[0],
              lab_b[1], lab_b[2], ps::delta_e2000(lab_a, lab_b));
  return tool::kExitOk;
}

}  // namespace

// long on purpose: the command line: each subcommand's options beside its call, as the other tools' mains.
int main(int argc, char** argv) {
  const std::string program = "prizma-metamer";
  CLI::App app{"Designs metamers and lights that hide or reveal the difference between two materials.\n"
               "Spectra are spec strings: D65, A, F11, LED-B3, cc:<patch>, gaussian:550:20, box:500:560,\n"
               "blackbody:3200K, csv:file.csv, 0.5, SPEC*0.5.",
               program};
  app.set_version_flag("--version", ps::prizma_version());
  // Examples (tests/e2e/docs/check_help.py checks that every option they use exists).
  app.footer("Examples:\n"
             "  prizma-metamer metamer --albedo cc:4 --match-light D65 --split-light F11 -o metamer.csv\n"
             "  prizma-metamer light --albedo-a cc:4 --albedo-b csv:metamer.csv --hide --reference A -o hide.csv\n"
             "  prizma-metamer weights --light D65 --bins linear:400:700:12 -o d65.csv\n"
             "Docs: share/doc/prizma/metamerism.md; man prizma-metamer.");
  app.require_subcommand(1);
  // Global options may come before or after the subcommand (prizma-metamer weights --bins … too).
  app.fallthrough();
  CommonOptions common;
  app.add_option("--bins", common.bins,
                 "bins the colours are computed in, e.g. a render's 'linear:380:780:16' (default: 1 nm, 380-780 nm)");
  app.add_option("--cmf", common.cmf, "observer: 1931, 1964, 2012-2, 2012-10")->capture_default_str();
  app.add_flag("-q,--quiet", common.quiet, "metamer, light: no summary or table on stdout (the CSV is written)");
  app.add_flag("-v,--verbose", common.verbose, "print the observer, bins and data folder used");
  // Accepted like the other tools' (scripts pass it to every tool) but not offered in --help: the
  // designs are small serial solves (milliseconds) with nothing to run in parallel.
  app.add_option("--threads", common.threads, "accepted and ignored: the designs run on one thread")
      ->check(CLI::NonNegativeNumber)
      ->group("");

  MetamerCommand metamer;
  CLI::App* sub_metamer = app.add_subcommand(
      "metamer", "design a smooth reflectance in [0,1] matching --albedo under --match-light, different under --split-light");
  sub_metamer->add_option("--albedo", metamer.albedo, "the reflectance to match")->required();
  sub_metamer->add_option("--match-light", metamer.match_light, "light under which both look the same")->required();
  sub_metamer->add_option("--split-light", metamer.split_light, "light under which they should differ most")->required();
  sub_metamer->add_option("-o,--output", metamer.output, "output CSV (nm, reflectance)")->required()->check(tool::non_empty_path());
  sub_metamer->add_option("--basis", metamer.basis, "number of B-spline basis functions (smoothness)")
      ->capture_default_str()->check(CLI::Range(6, 200));
  sub_metamer->add_option("--min", metamer.min_value, "lower bound of the reflectance")->capture_default_str();
  sub_metamer->add_option("--max", metamer.max_value, "upper bound of the reflectance")->capture_default_str();

  LightCommand light;
  CLI::App* sub_light = app.add_subcommand(
      "light", "design a light (same luminance as --reference) that hides or reveals the difference of two albedos");
  sub_light->add_option("--albedo-a", light.albedo_a, "first albedo spectrum");
  sub_light->add_option("--albedo-b", light.albedo_b, "second albedo spectrum");
  sub_light->add_option("--scene", light.scene, "scene JSON to read materials' albedos from")->check(tool::non_empty_path());
  sub_light->add_option("--material-a", light.material_a, "first material's name (or index) in --scene");
  sub_light->add_option("--material-b", light.material_b, "second material's name (or index) in --scene");
  sub_light->add_flag("--hide", light.hide, "make the two look the same (dE00 -> 0)");
  sub_light->add_flag("--reveal", light.reveal, "make the two look as different as possible");
  sub_light->add_option("--reference", light.reference, "reference light (luminance, comparison)")->capture_default_str();
  sub_light->add_option("--primaries", light.primaries, "restrict to a non-negative mix of these spectra (comma separated)")
      ->delimiter(',');
  sub_light->add_option("--basis", light.basis, "free-form light: number of B-spline basis functions")
      ->capture_default_str()->check(CLI::Range(6, 200));
  sub_light->add_option("--max-power-ratio", light.max_power_ratio,
                        "radiant power at most this many times the reference's at equal luminance (0: no limit)")
      ->capture_default_str()->check(CLI::NonNegativeNumber);
  sub_light->add_option("-o,--output", light.output, "output CSV (nm, relative spectral power)")
      ->required()
      ->check(tool::non_empty_path());

  DeltaECommand delta;
  CLI::App* sub_delta = app.add_subcommand(
      "delta-e", "CIEDE2000 between two XYZ colours of an image relit under --light (white: a perfect reflector)");
  sub_delta->add_option("--light", delta.light, "the light the image was relit with")->capture_default_str();
  sub_delta->add_option("--xyz-a", delta.xyz_a, "X,Y,Z of the first colour")->required()->expected(3)->delimiter(',');
  sub_delta->add_option("--xyz-b", delta.xyz_b, "X,Y,Z of the second colour")->required()->expected(3)->delimiter(',');

  WeightsCommand weights;
  CLI::App* sub_weights = app.add_subcommand(
      "weights", "write the relighter's X,Y,Z weights per bin for --light (white-normalised: sum of Y = 1)");
  sub_weights->add_option("--light", weights.light, "light spectrum")->capture_default_str();
  sub_weights->add_option("-o,--output", weights.output, "output CSV (lo_nm, hi_nm, X, Y, Z)")->required()->check(tool::non_empty_path());

  TabulateCommand tabulate;
  CLI::App* sub_tabulate = app.add_subcommand("tabulate", "write a spectrum spec as a CSV table (for scripts and plots)");
  sub_tabulate->add_option("--spectrum", tabulate.spectrum, "spectrum spec")->required();
  sub_tabulate->add_option("--from", tabulate.from_nm, "first wavelength (nm)")->capture_default_str();
  sub_tabulate->add_option("--to", tabulate.to_nm, "last wavelength (nm)")->capture_default_str();
  sub_tabulate->add_option("--step", tabulate.step_nm, "step (nm)")->capture_default_str();
  sub_tabulate->add_option("-o,--output", tabulate.output, "output CSV")->required()->check(tool::non_empty_path());

  if (const int code = tool::parse_command_line(app, argc, argv); code >= 0) return code;
  return tool::run_tool(program, [&]() {
    // Only the chosen subcommand's output is set; refuse an unwritable one before any work.
    for (const std::string* out : {&metamer.output, &light.output, &tabulate.output, &weights.output})
      if (!out->empty()) ps::check_output_file(*out, "--output");
    if (*sub_metamer) return run_metamer(metamer, common);
    if (*sub_light) return run_light(light, common);
    if (*sub_tabulate) return run_tabulate(tabulate);
    if (*sub_weights) return run_weights(weights, common);
    return run_delta_e(delta, common);
  });
}
