#include "prizma/relight/batch_file.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <climits>
#include <cmath>
#include <fstream>
#include <iterator>
#include <set>

#include "prizma/spectral/relight_image.h"
#include "prizma/spectral/atomic_file.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/input_file.h"

namespace prizma::relight {

namespace fs = std::filesystem;
using nlohmann::json;
using spectral::InputError;

namespace {

const std::set<std::string> kSettingKeys = {"lights", "exposure", "cmf",        "adapt",   "absolute",
                                            "display", "view",    "colourSpace", "colorSpace", "bitDepth"};

// Applies the keys of one JSON object (an output or "defaults") onto settings. `where` names it;
// `names` gets the names of the values it sets, for RelightSettings::validate.
void apply_keys(const json& obj, const std::string& where, const RelightSession& session, const fs::path& base_dir,
                RelightSettings& s, RelightSettingNames& names) {
  if (obj.is_object() && obj.contains("colourSpace") && obj.contains("colorSpace")) {
    throw InputError(where + ".colorSpace", "give colourSpace or colorSpace (the same key), not both");
  }
  for (const auto& [key, value] : obj.items()) {
    const std::string input = where + "." + key;
    if (key == "file") continue;
    if (!kSettingKeys.count(key)) {
      throw InputError(input, "unknown key (known: file, lights, exposure, cmf, adapt, absolute, display, view, "
                              "colourSpace (or colorSpace), bitDepth)");
    }
    try {
      if (key == "lights") {
        if (value.is_string()) {
          session.set_every_light(s.lights, parse_light_spec(value.get<std::string>(), {input, base_dir}));
        } else if (value.is_object()) {
          for (const auto& [name, spec] : value.items()) {
            if (!spec.is_string()) throw InputError(input + "." + name, "must be a spectrum spec string");
            const int l = session.light_index(name, input);
            s.lights[static_cast<std::size_t>(l)] = parse_light_spec(spec.get<std::string>(), {input + "." + name, base_dir});
          }
        } else {
          throw InputError(input, "must be a spec string (every light) or an object {\"name\": \"spec\"}");
        }
      } else if (key == "exposure") {
        s.relight.exposure_ev = value.get<double>();  // its range: RelightSettings::validate below
        names.exposure = input;
      } else if (key == "cmf") {
        s.relight.cmf = spectral::parse_observer(value.get<std::string>(), input);
      } else if (key == "adapt") {
        s.relight.adapt_to_d65 = value.get<bool>();
      } else if (key == "absolute") {
        s.relight.units = value.get<bool>() ? spectral::LightUnits::Absolute : spectral::LightUnits::RelativeToWhite;
      } else if (key == "display") {
        s.output.display.display = value.get<std::string>();
      } else if (key == "view") {
        s.output.display.view = value.get<std::string>();
      } else if (key == "colourSpace" || key == "colorSpace") {
        s.output.display.colour_space = value.get<std::string>();
      } else if (key == "bitDepth") {
        // A JSON integer that an int holds: nlohmann would truncate 8.7 and wrap 4294967304 to 8. The
        // value's range is RelightSettings::validate's (below).
        if (!value.is_number_integer() || value < INT_MIN || value > INT_MAX) {
          throw InputError(input, "must be 8 or 16 (got " + value.dump() + ")");
        }
        s.output.bit_depth = value.get<int>();
        names.bit_depth = input;
      }
    } catch (const json::exception&) {
      throw InputError(input, "wrong type: " + value.dump());
    }
  }
}

}  // namespace

std::vector<BatchOutput> read_batch_file(const fs::path& path, const RelightSession& session,
                                         const RelightSettings& base) {
  const std::string name = path.string();
  spectral::require_regular_file(path, "a batch file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(name, "cannot open batch file");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  spectral::check_json_depth(text, name);
  json doc;
  try {
    doc = json::parse(text);
  } catch (const json::exception& e) {
    throw InputError(name, std::string("not valid JSON: ") + e.what());
  }
  if (!doc.is_object() || !doc.contains("outputs") || !doc["outputs"].is_array() || doc["outputs"].empty()) {
    throw InputError(name, "expected an object with a non-empty \"outputs\" array");
  }
  for (const auto& [key, value] : doc.items()) {
    if (key != "outputs" && key != "defaults") throw InputError(name + ": " + key, "unknown key (known: defaults, outputs)");
  }
  const fs::path base_dir = path.parent_path();
  RelightSettings defaults = base;
  RelightSettingNames default_names;
  if (doc.contains("defaults")) {
    if (!doc["defaults"].is_object()) throw InputError(name + ": defaults", "must be an object");
    if (doc["defaults"].contains("file")) throw InputError(name + ": defaults.file", "not allowed in defaults");
    apply_keys(doc["defaults"], name + ": defaults", session, base_dir, defaults, default_names);
  }

  std::vector<BatchOutput> outputs;
  std::vector<std::pair<fs::path, std::string>> files;  // (file, input naming it)
  const json& list = doc["outputs"];
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string where = name + ": outputs[" + std::to_string(i) + "]";
    const json& entry = list[i];
    if (!entry.is_object()) throw InputError(where, "must be an object");
    if (!entry.contains("file") || !entry["file"].is_string() || entry["file"].get<std::string>().empty()) {
      throw InputError(where + ".file", "missing (the output image's path)");
    }
    BatchOutput out;
    const fs::path file = entry["file"].get<std::string>();
    out.file = file.is_absolute() ? file : base_dir / file;
    out.settings = defaults;
    RelightSettingNames names = default_names;
    apply_keys(entry, where, session, base_dir, out.settings, names);
    // Validate now so that a bad entry stops the batch before anything is written.
    out.settings.validate(names);
    spectral::check_output_path(out.file, where + ".file");
    spectral::RelightMatrix check(session.image().bins, out.settings.lights, out.settings.relight);
    const spectral::OutputFormat format = spectral::output_format_for(out.file, where + ".file");
    try {
      spectral::check_output_options(format, out.settings.output);
    } catch (const InputError& e) {
      throw InputError(where, e.what());
    }
    files.emplace_back(out.file, where + ".file");
    outputs.push_back(std::move(out));
  }
  // Two entries writing one file ("a.png" and "./a.png", links to one file) would lose one image.
  spectral::check_distinct_outputs(files);
  return outputs;
}

void run_batch(RelightSession& session, const std::vector<BatchOutput>& outputs, std::ostream* log,
               spectral::OutputGroup* group) {
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const BatchOutput& out = outputs[i];
    session.apply(out.settings);
    const double ms = session.relight();
    session.save(out.file, "outputs[" + std::to_string(i) + "].file", group);
    if (log) *log << "wrote " << out.file.string() << " (relit in " << ms << " ms)\n";
  }
}

}  // namespace prizma::relight
