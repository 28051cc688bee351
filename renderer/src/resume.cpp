// prizma:renderOptions and --resume (resume.h).
#include "prizma/render/resume.h"

#include <nlohmann/json.hpp>
#include <type_traits>

#include "prizma/render/render.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/spectral_exr.h"

namespace prizma::render {
namespace {

using spectral::InputError;
using nlohmann::json;

std::string shown(const json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); }

}  // namespace

void apply_overrides(Scene& scene, const RenderOverrides& o, const std::string& input_prefix) {
  auto& st = scene.settings;
  if (o.width) scene.camera.width = *o.width;
  if (o.height) scene.camera.height = *o.height;
  if (o.bins) {
    st.bins = spectral::BinLayout::parse(*o.bins, input_prefix + "bins");
    spectral::check_exr_bin_names(st.bins, input_prefix + "bins");
  }
  if (o.seed) st.seed = *o.seed;
  if (o.wavelength_sampling)
    st.wavelength_sampling = parse_wavelength_sampling(*o.wavelength_sampling, input_prefix + "wavelength-sampling");
  if (o.sampler) st.sampler = parse_sampler(*o.sampler, input_prefix + "sampler");
  if (o.target_error) st.target_error = *o.target_error;
  if (o.no_majorant_grid) st.use_majorant_grid = false;
  if (o.variance) st.write_variance = true;
  if (o.features) st.write_guides = true;
}

std::string overrides_to_json(const RenderOverrides& o) {
  json j = json::object();
  if (o.width) j["width"] = *o.width;
  if (o.height) j["height"] = *o.height;
  if (o.bins) j["bins"] = *o.bins;
  if (o.seed) j["seed"] = std::to_string(*o.seed);  // a string: JSON readers lose integers above 2^53
  if (o.wavelength_sampling) j["wavelength-sampling"] = *o.wavelength_sampling;
  if (o.sampler) j["sampler"] = *o.sampler;
  if (o.target_error) j["target-error"] = *o.target_error;
  if (o.no_majorant_grid) j["no-majorant-grid"] = true;
  if (o.variance) j["variance"] = true;
  if (o.features) j["features"] = true;
  if (o.half) j["half"] = true;
  if (o.samples) j["samples"] = o.samples->to_string();
  return j.dump();
}

RenderOverrides overrides_from_json(const std::string& text, const std::string& input) {
  const json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (!j.is_object()) throw InputError(input, "is not a JSON object");
  RenderOverrides o;
  auto bad = [&](const std::string& key) {
    return InputError(input, "\"" + key + "\": unexpected value " + shown(j.at(key)));
  };
  for (const auto& [key, v] : j.items()) {
    if (key == "width" || key == "height") {
      if (!v.is_number_integer() || v.get<std::int64_t>() < 1 || v.get<std::int64_t>() > (1 << 30)) throw bad(key);
      (key == "width" ? o.width : o.height) = v.get<int>();
    } else if (key == "bins" || key == "wavelength-sampling" || key == "sampler") {
      if (!v.is_string()) throw bad(key);
      (key == "bins" ? o.bins : key == "sampler" ? o.sampler : o.wavelength_sampling) = v.get<std::string>();
    } else if (key == "seed") {
      if (!v.is_string()) throw bad(key);
      try {
        std::size_t used = 0;
        const std::string s = v.get<std::string>();
        o.seed = std::stoull(s, &used);
        if (used != s.size() || s.front() == '-') throw bad(key);
      } catch (const std::logic_error&) {
        throw bad(key);
      }
    } else if (key == "target-error") {
      if (!v.is_number() || !(v.get<double>() >= 0.0)) throw bad(key);
      o.target_error = v.get<double>();
    } else if (key == "features") {
      if (!v.is_boolean()) throw bad(key);
      o.features = v.get<bool>();
    } else if (key == "no-majorant-grid" || key == "variance" || key == "half") {
      if (!v.is_boolean()) throw bad(key);
      (key == "variance" ? o.variance : key == "half" ? o.half : o.no_majorant_grid) = v.get<bool>();
    } else if (key == "samples") {
      if (!v.is_string()) throw bad(key);
      o.samples = SampleRange::parse(v.get<std::string>(), input + " \"samples\"");
    } else {
      throw InputError(input, "unknown option \"" + key + "\"");
    }
  }
  return o;
}

// long on purpose: the resume rules in order (scene, options, estimator, target), each refusal naming the option.
ResumePlan plan_resume(const ResumeRequest& req) {
  const std::string file = req.file.string();
  ResumePlan plan;
  spectral::ExrReadOptions read_options;
  read_options.verify_checksum = req.verify_checksum;
  plan.previous = spectral::read_spectral_exr(req.file, read_options);
  require_raw_samples(plan.previous, file);
  const auto& info = plan.previous.info;
  if (!info.is_prizma || info.sample_range.empty())
    throw InputError(file, "has no prizma:sampleRange: not a prizma-render file that can be resumed");
  const auto ranges = parse_sample_ranges(info.sample_range, file + ": prizma:sampleRange");
  if (ranges.size() != 1)
    throw InputError(file, "holds samples " + info.sample_range +
                               ", not one contiguous range: render the gap as a shard and merge instead");
  plan.held = ranges.front();

  // The scene: the one given, else the recorded one; it must be the scene the file was rendered from.
  const bool recorded = !info.render_options.empty();
  std::filesystem::path scene_path = req.scene;
  if (scene_path.empty()) scene_path = info.scene_path;
  if (scene_path.empty())
    throw InputError(file, "does not record its scene file (prizma:scenePath, files of Prizma before 0.2): "
                           "give the scene as well");
  plan.scene = load_scene(scene_path);
  if (!info.scene_hash.empty() && plan.scene.hash != info.scene_hash)
    throw InputError(scene_path.string(), "has changed since " + file + " was rendered (scene hash " +
                                              plan.scene.hash + ", the file records " + info.scene_hash +
                                              "): resuming would mix two scenes");

  // Options: the recorded ones; one given again must say the same.
  const RenderOverrides& given = req.given;
  if (given.samples) throw InputError("--samples", "cannot be combined with --resume (--spp N sets the total)");
  RenderOverrides o = recorded ? overrides_from_json(info.render_options, file + ": prizma:renderOptions")
                               : given;
  if (recorded) {
    auto check = [&](const char* name, bool given_set, bool same, const std::string& was) {
      if (given_set && !same)
        throw InputError(std::string("--") + name, file + " was rendered with " + was +
                                                       ": a resumed render cannot change it");
    };
    auto opt = [](const auto& v) {
      if (!v) return std::string("the scene's value");
      if constexpr (std::is_same_v<std::decay_t<decltype(*v)>, std::string>)
        return *v;
      else
        return std::to_string(*v);
    };
    check("width", given.width.has_value(), given.width == o.width, "width " + opt(o.width));
    check("height", given.height.has_value(), given.height == o.height, "height " + opt(o.height));
    check("bins", given.bins.has_value(), given.bins == o.bins, "bins " + opt(o.bins));
    check("seed", given.seed.has_value(), given.seed == o.seed, "seed " + opt(o.seed));
    check("wavelength-sampling", given.wavelength_sampling.has_value(),
          given.wavelength_sampling == o.wavelength_sampling, "wavelength sampling " + opt(o.wavelength_sampling));
    check("sampler", given.sampler.has_value(), given.sampler == o.sampler, "sampler " + opt(o.sampler));
    check("target-error", given.target_error.has_value(), given.target_error == o.target_error,
          "target error " + opt(o.target_error));
    check("no-majorant-grid", given.no_majorant_grid, o.no_majorant_grid, "the majorant grid");
    check("variance", given.variance, o.variance || !plan.previous.lights.front().variance.empty(),
          "no variance layers");
    check("features", given.features, o.features || !plan.previous.guides.empty(), "no guide layers");
    o.half = o.half || given.half;
  }
  apply_overrides(plan.scene, o, recorded ? file + ": prizma:renderOptions " : "--");
  // The estimator the held samples were rendered with, whatever the default has become since
  // (auto resolves by the scene; a file of an earlier version holds spectral tracking's samples).
  if (!info.wavelength_sampling.empty())
    plan.scene.settings.wavelength_sampling = parse_wavelength_sampling(info.wavelength_sampling, file + ": prizma:wavelengthSampling");
  // Likewise spectral MIS's lane groups, whatever `auto` resolves to now.
  if (plan.scene.settings.wavelength_sampling == WavelengthSampling::SpectralMis)
    plan.scene.settings.mis_lane_groups = recorded_mis_lane_groups(info);
  if (!plan.previous.lights.empty() && !plan.previous.lights.front().variance.empty())
    plan.scene.settings.write_variance = true;
  if (!plan.previous.guides.empty()) plan.scene.settings.write_guides = true;

  // The target: --spp N is the total from the file's first sample; else the recorded target; else
  // (older files) the scene's sample count.
  if (req.spp) {
    plan.target = SampleRange::starting_at(plan.held.begin, *req.spp, "--spp");
  } else if (o.samples && o.samples->begin == plan.held.begin) {
    plan.target = *o.samples;
  } else {
    const std::int64_t scene_spp = plan.scene.settings.sample_end - plan.scene.settings.sample_begin;
    plan.target = SampleRange::starting_at(plan.held.begin, scene_spp, "samples");
  }
  if (plan.target.end < plan.held.end)
    throw InputError(req.spp ? "--spp" : file, file + " already holds samples " + plan.held.to_string() +
                                                   ", more than the " + plan.target.to_string() + " asked for");
  plan.complete = plan.target.end == plan.held.end;
  plan.scene.settings.sample_begin = plan.held.end;
  plan.scene.settings.sample_end = plan.complete ? plan.held.end + 1 : plan.target.end;
  o.samples = plan.target;
  plan.overrides = o;
  return plan;
}

}  // namespace prizma::render
