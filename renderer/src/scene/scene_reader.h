#pragma once
// The scene file's reader (internal to scene/): the JSON → Scene checks every section shares (Reader:
// a field path in every message, typed reads, spectra, file paths), the limits more than one section
// uses, and the reader of each section, one file per concept: scene_volume.cpp (the volume, its
// clip planes, interpolation and value normalisation), scene_materials.cpp (materials and the
// transfer-function image), scene_camera.cpp, scene_lights.cpp, scene_settings.cpp (bins and
// sampling), scene_json.cpp (parsing and -D overrides), scene_hash.cpp; scene_loader.cpp puts them
// together (load_scene). Every error is an InputError whose input is "<file>: <field path>".
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "prizma/render/scene.h"
#include "prizma/render/transfer_function.h"
#include "prizma/render/volume.h"
#include "prizma/spectral/spectrum.h"
#include "prizma/spectral/spectrum_spec.h"

namespace prizma::render::scene_file {

using nlohmann::json;

// Limits shared by a section and the command-line overrides of its fields (integer_field_range).
constexpr int kMaxImageSide = 16384;
constexpr std::int64_t kMaxSamples = std::int64_t{1} << 40;
constexpr std::int64_t kMaxBounces = 1000000;

// A number as messages show it (10 significant digits).
std::string num(double v);

// The unit vector along v, or nothing for the zero vector: every direction a scene gives (a light's,
// a spot's axis, a clip plane's normal, the camera's up) goes through here. v is scaled by its largest
// component first, so that a length of 1e-300 (whose norm underflows to 0) or 1e300 (overflows)
// keeps its direction. `along`, when given, is divided by v's length in the same two steps (a clip
// plane's offset; it may become ±inf, which keeps the plane's condition exact).
std::optional<Eigen::Vector3d> unit_direction(const Eigen::Vector3d& v, double* along = nullptr);

// Reading JSON with a field path for every message.
class Reader {
 public:
  Reader(std::string file, std::filesystem::path base_dir, std::vector<std::string> overridden = {})
      : m_file(std::move(file)), m_base(std::move(base_dir)), m_overridden(std::move(overridden)) {}

  const std::string& file() const { return m_file; }
  const std::filesystem::path& base_dir() const { return m_base; }
  // "<file>: <path>", or "-D <path>" for a field set (or inside a value set) by -D KEY=VALUE, or the
  // path alone when there is no file (a command-line option).
  std::string input(const std::string& path) const;

  [[noreturn]] void fail(const std::string& path, const std::string& reason) const;

  static std::string join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }
  static std::string index(const std::string& path, std::size_t i) { return path + "[" + std::to_string(i) + "]"; }
  // "<type> <text>" of a value, its text cut at 40 characters.
  static std::string describe(const json& j);

  // An object whose keys are all in `known` (an unknown one is named, with the list).
  void expect_object(const json& j, const std::string& path, std::initializer_list<const char*> known) const;
  // A finite number; an integer in [lo, hi]; a string; an array of 3 numbers; a number > 0.
  double number(const json& j, const std::string& path) const;
  std::int64_t integer(const json& j, const std::string& path, std::int64_t lo, std::int64_t hi) const;
  std::string string(const json& j, const std::string& path) const;
  std::array<double, 3> vec3(const json& j, const std::string& path) const;
  double positive(const json& j, const std::string& path) const;
  // A file path relative to the scene's folder.
  std::filesystem::path file_path(const json& j, const std::string& path) const;
  // A spectrum: a spec string, a number, or {"spectrum": SPEC, "scale": number}, of a quantity with
  // the sign `values` (spectrum_spec.h: only the anisotropy is signed). A number is checked by the
  // field's own range (validate_material, …).
  spectral::Spectrum spectrum(const json& j, const std::string& path,
                              spectral::SpectrumValues values = spectral::SpectrumValues::NonNegative) const;

 private:
  std::string m_file;
  std::filesystem::path m_base;
  std::vector<std::string> m_overridden;  // field paths set by -D, as this reader names them
};

// The sections (scene-format.md), in the order load_scene reads them.
std::vector<Light> read_lights(const Reader& rd, const json& j);
Camera read_camera(const Reader& rd, const json& j);
void read_settings(const Reader& rd, const json& root, RenderSettings& s);
std::uint64_t read_seed(const Reader& rd, const json& j, const std::string& path);
Interpolation read_interpolation(const Reader& rd, const json& volume);
std::vector<ClipPlane> read_clip(const Reader& rd, const json& volume);
Volume read_volume(const Reader& rd, const json& j);
ValueNormalisation read_normalisation(const Reader& rd, const json& root, const Volume& vol);
TransferFunction read_materials(const Reader& rd, const json& j, const ValueNormalisation& norm);
TransferFunction read_tf_image(const Reader& rd, const json& j, const ValueNormalisation& norm);
// Refuses a medium whose largest extinction × density the trackers cannot step through, naming the
// material's extinction (or the transfer function's extinction_scale).
void check_trackable(const Reader& rd, const Medium& med, bool has_materials);
// The emission layer: one light for every emitting material, only when some material emits (named
// by the scene's "emission_light", default "emission").
void add_emission_light(const Reader& rd, const json& root, Scene& scene);

// The JSON of a scene file: duplicate keys refused, syntax errors with line and column.
json parse_json(const std::string& text, const std::string& file);
// Applies one -D KEY=VALUE to the scene's JSON; returns the field's path as Reader names it.
std::string apply_scene_override(json& root, const SceneOverride& o);
// A command-line value as JSON (so that "1e9", "8.7" and "-1" are what they are), or InputError.
json override_json(const std::string& text, const std::string& option, const char* expected);
// The integer range of a scene field, shared by the scene reader and the command-line overrides.
std::pair<std::int64_t, std::int64_t> integer_field_range(const std::string& field);

}  // namespace prizma::render::scene_file
