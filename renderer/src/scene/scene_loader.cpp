// load_scene: the JSON scene file (docs/scene-format.md) → a validated Scene, each section read by
// its own reader (scene_reader.h), the cheap sections first so that a typo is reported before a
// large volume is read.
#include <algorithm>
#include <cctype>
#include <cstring>
#include <fstream>
#include <sstream>

#include "prizma/render/volume_inspection.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/input_file.h"
#include "scene_hash.h"
#include "scene_reader.h"

namespace prizma::render {

using spectral::InputError;

namespace {

using scene_file::json;
using scene_file::Reader;

// The file's JSON with the -D overrides applied, and the field paths they set (a field set twice is
// refused).
json overridden_json(const std::string& text, const std::string& file, const std::vector<SceneOverride>& overrides,
                     std::vector<std::string>& overridden) {
  json root = scene_file::parse_json(text, file);
  if (!overrides.empty() && !root.is_object()) throw InputError(file, "must be an object (the scene) for -D");
  for (const SceneOverride& o : overrides) {
    const std::string field = scene_file::apply_scene_override(root, o);
    if (std::find(overridden.begin(), overridden.end(), field) != overridden.end())
      throw InputError("-D " + o.key, "is given twice");
    overridden.push_back(field);
  }
  return root;
}

// The top level: known fields, the required ones, materials or a transfer-function image.
void check_top_level(const Reader& rd, const json& root) {
  if (root.contains("normalisation") && root.contains("normalization"))
    rd.fail("normalization", "give normalisation or normalization (the same field), not both");
  rd.expect_object(root, "",
                   {"description", "volume", "normalisation", "normalization", "materials", "transfer_function", "camera", "lights",
                    "bins", "samples", "seed", "max_bounces", "wavelength_sampling", "sampler", "event_probabilities", "mis_lane_groups", "target_error", "output",
                    "emission_light"});
  if (root.contains("description")) rd.string(root.at("description"), "description");
  if (!root.contains("volume")) rd.fail("volume", "is required");
  if (!root.contains("lights")) rd.fail("lights", "is required (at least one light)");
  const bool has_materials = root.contains("materials");
  if (has_materials == root.contains("transfer_function")) {
    rd.fail(has_materials ? "transfer_function" : "materials",
            has_materials ? "give either materials or transfer_function, not both"
                          : "is required (or a transfer_function image)");
  }
}

// The scene in `text`, named `file` in messages; `path` is its source (relative paths resolve in its
// folder; the default output is beside it).
Scene scene_from_text(const std::string& text, const std::string& file, const std::filesystem::path& path,
                      const std::vector<SceneOverride>& overrides) {
  std::vector<std::string> overridden;
  const json root = overridden_json(text, file, overrides, overridden);
  const Reader rd(file, path.parent_path(), overridden);
  check_top_level(rd, root);

  Scene scene;
  scene.source = path;
  // The cheap parts first, so a typo is reported before a large volume is read.
  scene.lights = scene_file::read_lights(rd, root.at("lights"));
  if (root.contains("camera")) scene.camera = scene_file::read_camera(rd, root.at("camera"));
  scene_file::read_settings(rd, root, scene.settings);
  scene.output = path.parent_path() / (path.stem().string() + ".exr");
  if (root.contains("output")) scene.output = rd.file_path(root.at("output"), "output");

  const Interpolation interpolation = scene_file::read_interpolation(rd, root.at("volume"));
  std::vector<ClipPlane> clip = scene_file::read_clip(rd, root.at("volume"));
  const Volume vol = scene_file::read_volume(rd, root.at("volume"));
  scene_file::SceneHash hash(text, overrides, vol);  // the voxels hashed beside the classification

  const bool has_materials = root.contains("materials");
  const ValueNormalisation norm = scene_file::read_normalisation(rd, root, vol);
  const TransferFunction tf = has_materials ? scene_file::read_materials(rd, root.at("materials"), norm)
                                            : scene_file::read_tf_image(rd, root.at("transfer_function"), norm);
  scene.medium = build_medium(vol, tf, rd.input("volume"), interpolation);
  scene.medium.clip = std::move(clip);
  scene.volume_note = vol.orientation;
  scene.warnings = vol.warnings;
  scene_file::check_trackable(rd, scene.medium, has_materials);
  scene_file::add_emission_light(rd, root, scene);
  scene.hash = hash.finish(scene);
  return scene;
}

}  // namespace

SceneOverride parse_scene_override(const std::string& text) {
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("-D " + text, "expected KEY=VALUE, e.g. -D camera.fov_deg=30 (KEY a field path of the scene)");
  return SceneOverride{text.substr(0, eq), text.substr(eq + 1)};
}

std::int64_t scene_integer_override(const std::string& text, const std::string& field, const std::string& option) {
  const auto [lo, hi] = scene_file::integer_field_range(field);
  const json j = scene_file::override_json(text, option, "an integer");
  return Reader("", {}).integer(j, option, lo, hi);
}

std::uint64_t scene_seed_override(const std::string& text, const std::string& option) {
  const json j = scene_file::override_json(text, option, "an integer ≥ 0");
  return scene_file::read_seed(Reader("", {}), j, option);
}

Scene load_scene(const std::filesystem::path& path, const std::vector<SceneOverride>& overrides) {
  const std::string file = path.string();
  spectral::require_regular_file(path, "a scene file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(file, "cannot open scene file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return scene_from_text(buffer.str(), file, path, overrides);
}

InspectedVolume load_for_inspection(const std::filesystem::path& path) {
  const std::string file = path.string();
  spectral::require_regular_file(path, "a scene or volume file");
  InspectedVolume out;
  out.input = file;
  std::string name = path.filename().string();
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::tolower(c); });
  const auto ends = [&](const char* e) { return name.size() >= std::strlen(e) && name.compare(name.size() - std::strlen(e), std::string::npos, e) == 0; };
  if (ends(".json")) {
    // The scene's volume and transfer function, read by the loader's own functions.
    std::ifstream in(path, std::ios::binary);
    std::stringstream buffer;
    buffer << in.rdbuf();
    const json root = scene_file::parse_json(buffer.str(), file);
    const Reader rd(file, path.parent_path());
    if (!root.is_object() || !root.contains("volume")) rd.fail("volume", "is required");
    out.volume = scene_file::read_volume(rd, root.at("volume"));
    out.from_scene = true;
    out.normalisation_given = (root.contains("normalisation") && root.at("normalisation").is_object()) ||
                              (root.contains("normalization") && root.at("normalization").is_object());
    out.normalisation = scene_file::read_normalisation(rd, root, out.volume);
    if (root.contains("materials")) out.transfer = scene_file::read_materials(rd, root.at("materials"), out.normalisation);
    else if (root.contains("transfer_function")) out.transfer = scene_file::read_tf_image(rd, root.at("transfer_function"), out.normalisation);
    return out;
  }
  // A volume file: the "volume" a scene would give for it.
  const char* type = ends(".nii") || ends(".nii.gz") ? "nifti" : ends(".raw") ? "raw" : ends(".vdb") ? "vdb" : nullptr;
  if (type == nullptr) {
    throw InputError(file, "not a scene or volume file this can inspect (known: .json, .nii, .nii.gz, .raw, .vdb)");
  }
  const Reader rd("", std::filesystem::path());  // the path as given: the loaders' messages name it so
  out.volume = scene_file::read_volume(rd, json{{"type", type}, {"path", file}});
  out.normalisation = auto_normalisation(out.volume);
  return out;
}

Scene load_scene_text(const std::string& text, const std::string& input, const std::filesystem::path& base_dir,
                      const std::vector<SceneOverride>& overrides) {
  return scene_from_text(text, input, base_dir / input, overrides);
}

}  // namespace prizma::render
