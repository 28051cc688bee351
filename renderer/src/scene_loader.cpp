// load_scene: the JSON scene file (docs/scene-format.md) → a validated Scene. Every error is an
// InputError whose input is "<file>: <field path>". Past 1000 lines because every field's reader
// shares the Reader below and its field paths; the lights (read_lights and its helpers, ~170 lines)
// are the next part to move into a file of their own.
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_group.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "prizma/render/scene.h"
#include "prizma/render/fluorescence.h"
#include "prizma/render/transfer_function.h"
#include "prizma/render/volume.h"
#include "prizma/render/volume_inspection.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/spectral_exr.h"
#include "prizma/spectral/input_file.h"
#include "prizma/spectral/light_spectrum.h"
#include "prizma/spectral/spectrum_spec.h"

namespace prizma::render {

using nlohmann::json;
using spectral::InputError;
using spectral::Spectrum;

namespace {

constexpr int kDefaultResolution = 128;
constexpr int kMaxImageSide = 16384;
constexpr std::size_t kMaxLightNameLength = 64;
constexpr std::int64_t kMaxSamples = std::int64_t{1} << 40;
// Densities are stored as float; extinction × density is what the trackers step through: one step
// per unit of optical depth, so a path crosses the volume (largest side 1, diagonal ≤ √3) in at
// most about kMaxExtinctionPerUnit · √3 steps. Beyond this a render would not end.
constexpr std::int64_t kMaxBounces = 1000000;
constexpr double kMaxDensity = 1e30;
constexpr double kMaxExtinctionPerUnit = 1e6;
// Emitted radiance Le at density 1: the tracer adds w·σa·density·Le/μ̄ per collision in float, with
// σt·density ≤ kMaxExtinctionPerUnit, so each term stays below 10¹² and a path's sum over its at most
// 2²⁸ steps below 10²¹ (3e38, float's largest, became NaN and then no light). A brighter emitter is
// the emission layer relit with a larger scale (--light emission=D65*1000).
constexpr double kMaxEmission = 1e6;
// Point-light positions and radii: |coordinate| ≤ this (the volume's largest side is 1 unit).
constexpr double kMaxLightCoordinate = 1e6;

// The unit vector along v, or nothing for the zero vector: every direction a scene gives (a light's,
// a spot's axis, a clip plane's normal, the camera's up) goes through here. v is scaled by its largest
// component first, so that a length of 1e-300 (whose norm underflows to 0) or 1e300 (overflows)
// keeps its direction. `along`, when given, is divided by v's length in the same two steps (a clip
// plane's offset; it may become ±inf, which keeps the plane's condition exact).
std::optional<Eigen::Vector3d> unit_direction(const Eigen::Vector3d& v, double* along = nullptr) {
  const double largest = v.cwiseAbs().maxCoeff();
  if (!(largest > 0.0)) return std::nullopt;
  const Eigen::Vector3d scaled = v / largest;
  const double norm = scaled.norm();
  if (along != nullptr) *along = *along / largest / norm;
  return Eigen::Vector3d(scaled / norm);
}

std::string num(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

// Reading JSON with a field path for every message.
class Reader {
 public:
  Reader(std::string file, std::filesystem::path base_dir, std::vector<std::string> overridden = {})
      : m_file(std::move(file)), m_base(std::move(base_dir)), m_overridden(std::move(overridden)) {}

  const std::string& file() const { return m_file; }
  const std::filesystem::path& base_dir() const { return m_base; }
  std::string input(const std::string& path) const {
    if (m_file.empty()) return path;  // a command-line option
    // A field set (or inside a value set) by -D KEY=VALUE is named as the option that set it.
    for (const std::string& o : m_overridden) {
      if (path == o || (path.size() > o.size() && path.compare(0, o.size(), o) == 0 &&
                        (path[o.size()] == '.' || path[o.size()] == '[')))
        return "-D " + path;
    }
    return path.empty() ? m_file : m_file + ": " + path;
  }

  [[noreturn]] void fail(const std::string& path, const std::string& reason) const {
    throw InputError(input(path), reason);
  }

  static std::string join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }
  static std::string index(const std::string& path, std::size_t i) { return path + "[" + std::to_string(i) + "]"; }

  static std::string describe(const json& j) {
    std::string text = j.dump();
    if (text.size() > 40) text = text.substr(0, 37) + "...";
    return std::string(j.type_name()) + " " + text;
  }

  void expect_object(const json& j, const std::string& path, std::initializer_list<const char*> known) const {
    if (!j.is_object()) fail(path, "must be an object (got " + describe(j) + ")");
    for (const auto& item : j.items()) {
      const std::string& key = item.key();  // not a structured binding: clang 14 cannot capture those
      if (std::none_of(known.begin(), known.end(), [&](const char* k) { return key == k; })) {
        std::string list;
        for (const char* k : known) list += (list.empty() ? "" : ", ") + std::string(k);
        fail(join(path, key), "unknown field (known: " + list + ")");
      }
    }
  }

  double number(const json& j, const std::string& path) const {
    if (!j.is_number()) fail(path, "must be a number (got " + describe(j) + ")");
    const double v = j.get<double>();
    if (!std::isfinite(v)) fail(path, "must be finite");
    return v;
  }
  std::int64_t integer(const json& j, const std::string& path, std::int64_t lo, std::int64_t hi) const {
    if (!j.is_number_integer()) fail(path, "must be an integer (got " + describe(j) + ")");
    if (j.is_number_unsigned() && j.get<std::uint64_t>() > static_cast<std::uint64_t>(INT64_MAX)) {
      fail(path, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "] (got " + j.dump() + ")");
    }
    const std::int64_t v = j.get<std::int64_t>();
    if (v < lo || v > hi) {
      fail(path, "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "] (got " + std::to_string(v) + ")");
    }
    return v;
  }
  std::string string(const json& j, const std::string& path) const {
    if (!j.is_string()) fail(path, "must be a string (got " + describe(j) + ")");
    return j.get<std::string>();
  }
  std::array<double, 3> vec3(const json& j, const std::string& path) const {
    if (!j.is_array() || j.size() != 3) fail(path, "must be an array of 3 numbers (got " + describe(j) + ")");
    return {number(j[0], index(path, 0)), number(j[1], index(path, 1)), number(j[2], index(path, 2))};
  }
  double positive(const json& j, const std::string& path) const {
    const double v = number(j, path);
    if (!(v > 0.0)) fail(path, "must be > 0 (got " + num(v) + ")");
    return v;
  }

  // A file path relative to the scene's folder.
  std::filesystem::path file_path(const json& j, const std::string& path) const {
    const std::string s = string(j, path);
    if (s.empty()) fail(path, "must not be empty");
    const std::filesystem::path p(s);
    return p.is_absolute() ? p : m_base / p;
  }

  // A spectrum: a spec string, a number, or {"spectrum": SPEC, "scale": number}, of a quantity with
  // the sign `values` (spectrum_spec.h: only the anisotropy is signed). A number is checked by the
  // field's own range (validate_material, …).
  Spectrum spectrum(const json& j, const std::string& path,
                    spectral::SpectrumValues values = spectral::SpectrumValues::NonNegative) const {
    if (j.is_number()) return Spectrum::constant(number(j, path));
    if (j.is_string()) {
      spectral::SpecContext ctx;
      ctx.input = input(path);
      ctx.base_dir = m_base;
      ctx.values = values;
      return spectral::parse_spectrum(j.get<std::string>(), ctx);
    }
    if (j.is_object()) {
      expect_object(j, path, {"spectrum", "scale"});
      if (!j.contains("spectrum")) fail(join(path, "spectrum"), "is required");
      const json& inner = j.at("spectrum");
      if (!inner.is_string() && !inner.is_number()) {
        fail(join(path, "spectrum"), "must be a spectrum spec string or a number (got " + describe(inner) + ")");
      }
      Spectrum s = spectrum(inner, join(path, "spectrum"), values);
      if (j.contains("scale")) s = s.scaled(positive(j.at("scale"), join(path, "scale")));
      return s;
    }
    fail(path, "must be a spectrum spec string, a number or {\"spectrum\": SPEC, \"scale\": number} (got " +
                   describe(j) + ")");
  }

 private:
  std::string m_file;
  std::filesystem::path m_base;
  std::vector<std::string> m_overridden;  // field paths set by -D, as this reader names them
};

// 64-bit FNV-1a.
class Fnv1a {
 public:
  void add(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) {
      m_h ^= p[i];
      m_h *= 0x100000001b3ULL;
    }
  }
  void add_spectrum(const Spectrum& s) {
    const double c = s.is_constant() ? s.eval(0.0) : 0.0;
    add(&c, sizeof c);
    add(s.wavelengths_nm().data(), s.wavelengths_nm().size() * sizeof(double));
    add(s.values().data(), s.values().size() * sizeof(double));
  }
  std::string hex() const {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(m_h));
    return buf;
  }

 private:
  std::uint64_t m_h = 0xcbf29ce484222325ULL;
};

Volume read_volume(const Reader& rd, const json& j) {
  const std::string path = "volume";
  if (!j.is_object()) rd.fail(path, "must be an object (got " + Reader::describe(j) + ")");
  if (!j.contains("type")) rd.fail(Reader::join(path, "type"), "is required (raw, nifti, vdb or procedural)");
  const std::string type = rd.string(j.at("type"), Reader::join(path, "type"));
  Volume vol;
  bool spacing_given = j.contains("spacing");
  std::array<double, 3> spacing{1.0, 1.0, 1.0};
  if (spacing_given) {
    const std::string sp = Reader::join(path, "spacing");
    spacing = rd.vec3(j.at("spacing"), sp);
    for (int a = 0; a < 3; ++a) {
      if (!(spacing[a] > 0.0)) rd.fail(Reader::index(sp, a), "must be > 0 (got " + num(spacing[a]) + ")");
    }
  }
  if (type == "procedural") {
    rd.expect_object(j, path, {"type", "name", "resolution", "spacing", "interpolation", "clip"});
    if (!j.contains("name")) rd.fail(Reader::join(path, "name"), "is required");
    const std::string name = rd.string(j.at("name"), Reader::join(path, "name"));
    const auto names = procedural_volume_names();
    if (std::find(names.begin(), names.end(), name) == names.end()) {
      std::string list;
      for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
      rd.fail(Reader::join(path, "name"), "unknown procedural volume \"" + name + "\" (known: " + list + ")");
    }
    const int res = j.contains("resolution")
                        ? static_cast<int>(rd.integer(j.at("resolution"), Reader::join(path, "resolution"), 2, 2048))
                        : kDefaultResolution;
    vol = make_procedural_volume(name, res);
  } else if (type == "raw") {
    rd.expect_object(j, path, {"type", "path", "dims", "voxel_type", "endianness", "spacing", "interpolation", "clip"});
    if (!j.contains("path")) rd.fail(Reader::join(path, "path"), "is required");
    RawVolumeSpec spec;
    spec.path = rd.file_path(j.at("path"), Reader::join(path, "path"));
    if (j.contains("dims")) {
      const std::string dp = Reader::join(path, "dims");
      const json& d = j.at("dims");
      if (!d.is_array() || d.size() != 3) rd.fail(dp, "must be an array of 3 integers (got " + Reader::describe(d) + ")");
      for (int a = 0; a < 3; ++a) spec.dims[a] = static_cast<int>(rd.integer(d[a], Reader::index(dp, a), 1, INT32_MAX));
    }
    if (j.contains("voxel_type")) {
      const std::string tp = Reader::join(path, "voxel_type");
      const std::string t = rd.string(j.at("voxel_type"), tp);
      if (t == "uint8" || t == "u8") spec.type = VoxelType::U8;
      else if (t == "uint16" || t == "u16") spec.type = VoxelType::U16;
      else if (t == "int16" || t == "i16") spec.type = VoxelType::I16;
      else if (t == "float32" || t == "f32") spec.type = VoxelType::F32;
      else rd.fail(tp, "unknown voxel type \"" + t + "\" (known: uint8, uint16, int16, float32, u8, u16, i16, f32)");
      spec.type_given = true;
    }
    if (j.contains("endianness")) {
      const std::string ep = Reader::join(path, "endianness");
      const std::string e = rd.string(j.at("endianness"), ep);
      if (e == "big") spec.big_endian = true;
      else if (e != "little") rd.fail(ep, "must be \"little\" or \"big\" (got \"" + e + "\")");
    }
    spec.spacing = spacing;
    vol = load_raw_volume(spec);
  } else if (type == "nifti") {
    rd.expect_object(j, path, {"type", "path", "spacing", "interpolation", "clip"});
    if (!j.contains("path")) rd.fail(Reader::join(path, "path"), "is required");
    vol = load_nifti_volume(rd.file_path(j.at("path"), Reader::join(path, "path")));
  } else if (type == "vdb") {
    rd.expect_object(j, path, {"type", "path", "grid", "spacing", "interpolation", "clip"});
    if (!j.contains("path")) rd.fail(Reader::join(path, "path"), "is required");
    const std::string grid = j.contains("grid") ? rd.string(j.at("grid"), Reader::join(path, "grid")) : "density";
    if (grid.empty()) rd.fail(Reader::join(path, "grid"), "must not be empty");
    vol = load_vdb_volume(rd.file_path(j.at("path"), Reader::join(path, "path")), grid);
  } else {
    rd.fail(Reader::join(path, "type"), "must be \"raw\", \"nifti\", \"vdb\" or \"procedural\" (got \"" + type + "\")");
  }
  if (spacing_given) vol.spacing = spacing;
  return vol;
}

// volume.clip: up to 64 planes {"normal": [x, y, z], "offset": d}; the medium is removed where
// dot(normal, p) > d, exactly as written (the normal need not be unit length; it is normalised with d).
std::vector<ClipPlane> read_clip(const Reader& rd, const json& j) {
  std::vector<ClipPlane> planes;
  if (!j.is_object() || !j.contains("clip")) return planes;
  const std::string path = "volume.clip";
  const json& c = j.at("clip");
  if (!c.is_array()) rd.fail(path, "must be an array of planes {\"normal\": [x, y, z], \"offset\": d} (got " + Reader::describe(c) + ")");
  if (c.size() > 64) rd.fail(path, "at most 64 clip planes (got " + std::to_string(c.size()) + ")");
  for (std::size_t i = 0; i < c.size(); ++i) {
    const std::string pp = Reader::index(path, i);
    rd.expect_object(c[i], pp, {"normal", "offset"});
    if (!c[i].contains("normal")) rd.fail(Reader::join(pp, "normal"), "is required");
    const auto n = rd.vec3(c[i].at("normal"), Reader::join(pp, "normal"));
    const double offset = c[i].contains("offset") ? rd.number(c[i].at("offset"), Reader::join(pp, "offset")) : 0.0;
    ClipPlane plane;
    plane.offset = offset;
    const auto unit = unit_direction(Eigen::Vector3d(n[0], n[1], n[2]), &plane.offset);
    if (!unit) rd.fail(Reader::join(pp, "normal"), "must not be the zero vector");
    plane.normal = *unit;
    planes.push_back(plane);
  }
  return planes;
}

// volume.interpolation: "trilinear" (default) or "nearest".
Interpolation read_interpolation(const Reader& rd, const json& j) {
  if (!j.is_object() || !j.contains("interpolation")) return Interpolation::Trilinear;
  const std::string ip = "volume.interpolation";
  const std::string v = rd.string(j.at("interpolation"), ip);
  if (v == "trilinear") return Interpolation::Trilinear;
  if (v == "nearest") return Interpolation::Nearest;
  rd.fail(ip, "must be \"trilinear\" or \"nearest\" (got \"" + v + "\")");
}

ValueNormalisation read_normalisation(const Reader& rd, const json& root, const Volume& vol) {
  // Both spellings; load_scene refuses a file that has both.
  const std::string path = root.contains("normalization") ? "normalization" : "normalisation";
  if (!root.contains(path)) return auto_normalisation(vol);
  const json& j = root.at(path);
  if (j.is_string()) {
    if (j.get<std::string>() != "auto") rd.fail(path, "must be \"auto\" or {\"min\": number, \"max\": number} (got " + j.dump() + ")");
    return auto_normalisation(vol);
  }
  rd.expect_object(j, path, {"min", "max"});
  if (!j.contains("min")) rd.fail(Reader::join(path, "min"), "is required");
  if (!j.contains("max")) rd.fail(Reader::join(path, "max"), "is required");
  ValueNormalisation n;
  n.min = rd.number(j.at("min"), Reader::join(path, "min"));
  n.max = rd.number(j.at("max"), Reader::join(path, "max"));
  if (!(n.max > n.min)) rd.fail(Reader::join(path, "max"), "must be > min (got " + num(n.max) + " ≤ " + num(n.min) + ")");
  return n;
}

// A material's "fluorescence": {"absorption": SPEC, "emission": SPEC, "quantum_yield": q}
// (docs/scene-format.md). The emission's scale does not matter (the renderer normalises its area).
void read_fluorescence(const Reader& rd, const json& j, const std::string& path, Material& m) {
  rd.expect_object(j, path, {"absorption", "emission", "quantum_yield"});
  for (const char* key : {"absorption", "emission", "quantum_yield"})
    if (!j.contains(key)) rd.fail(Reader::join(path, key), "is required");
  Fluorescence f;
  const std::string ap = Reader::join(path, "absorption");
  f.absorption = rd.spectrum(j.at("absorption"), ap);
  if (!(f.absorption.min_value() >= 0.0) || !std::isfinite(f.absorption.max_value()))
    rd.fail(ap, "must be ≥ 0 and finite at every wavelength (got values in [" + num(f.absorption.min_value()) + ", " +
                    num(f.absorption.max_value()) + "])");
  const std::string ep = Reader::join(path, "emission");
  f.emission = rd.spectrum(j.at("emission"), ep);
  if (!(f.emission.min_value() >= 0.0) || !std::isfinite(f.emission.max_value()))
    rd.fail(ep, "must be ≥ 0 and finite at every wavelength (got values in [" + num(f.emission.min_value()) + ", " +
                    num(f.emission.max_value()) + "])");
  if (!(fluorescence_emission_area(f.emission) > 0.0))
    rd.fail(ep, "has no area over 360–830 nm: the re-emitted photons need a spectrum to be drawn from");
  const std::string qp = Reader::join(path, "quantum_yield");
  f.quantum_yield = rd.number(j.at("quantum_yield"), qp);
  if (!(f.quantum_yield >= 0.0 && f.quantum_yield <= 1.0))
    rd.fail(qp, "must be in [0, 1], the fraction of absorbed photons re-emitted (got " + num(f.quantum_yield) + ")");
  m.fluorescent = true;
  m.fluorescence = std::move(f);
}

TransferFunction read_materials(const Reader& rd, const json& j, const ValueNormalisation& norm) {
  const std::string path = "materials";
  if (!j.is_array()) rd.fail(path, "must be an array of materials (got " + Reader::describe(j) + ")");
  if (j.empty()) rd.fail(path, "must have at least one material");
  if (j.size() > 65534) rd.fail(path, "at most 65534 materials are supported (got " + std::to_string(j.size()) + ")");
  const double inf = std::numeric_limits<double>::infinity();
  TransferFunction tf;
  std::set<std::string> names;
  for (std::size_t i = 0; i < j.size(); ++i) {
    const std::string mp = Reader::index(path, i);
    const json& mj = j[i];
    rd.expect_object(mj, mp, {"name", "range", "units", "albedo", "extinction", "anisotropy", "density", "emission",
                          "fluorescence"});
    Material m;
    m.name = mj.contains("name") ? rd.string(mj.at("name"), Reader::join(mp, "name")) : "material" + std::to_string(i);
    if (m.name.empty()) rd.fail(Reader::join(mp, "name"), "must not be empty");
    if (!names.insert(m.name).second) rd.fail(Reader::join(mp, "name"), "duplicate material name \"" + m.name + "\"");

    // Units of the range and the density ramp's values.
    bool normalised = false;
    if (mj.contains("units")) {
      const std::string up = Reader::join(mp, "units");
      const std::string u = rd.string(mj.at("units"), up);
      if (u == "normalised" || u == "normalized") normalised = true;
      else if (u != "raw") rd.fail(up, "must be \"raw\" or \"normalised\" (got \"" + u + "\")");
    }
    auto to_raw = [&](double v, bool is_lo) {
      if (!normalised) return v;
      // Values clamp to [0, 1] when normalised, so the ends reach past the normalisation range.
      if (is_lo && v <= 0.0) return -inf;
      if (!is_lo && v >= 1.0) return inf;
      return norm.from_unit(v);
    };

    MaterialRule rule;
    rule.material = static_cast<int>(i);
    if (mj.contains("range")) {
      const std::string rp = Reader::join(mp, "range");
      const json& r = mj.at("range");
      if (!r.is_array() || r.size() != 2) rd.fail(rp, "must be [lo, hi] (got " + Reader::describe(r) + ")");
      const double lo = rd.number(r[0], Reader::index(rp, 0));
      const double hi = rd.number(r[1], Reader::index(rp, 1));
      if (!(lo <= hi)) rd.fail(rp, "lo must be ≤ hi (got [" + num(lo) + ", " + num(hi) + "])");
      if (normalised && (lo < 0.0 || hi > 1.0)) {
        rd.fail(rp, "normalised values must be in [0, 1] (got [" + num(lo) + ", " + num(hi) + "])");
      }
      rule.value_lo = to_raw(lo, true);
      rule.value_hi = to_raw(hi, false);
    }

    const std::string ap = Reader::join(mp, "albedo");
    const std::string ep = Reader::join(mp, "extinction");
    if (!mj.contains("albedo")) rd.fail(ap, "is required");
    if (!mj.contains("extinction")) rd.fail(ep, "is required");
    m.albedo = rd.spectrum(mj.at("albedo"), ap);
    m.sigma_t_per_unit = rd.spectrum(mj.at("extinction"), ep);
    m.anisotropy = mj.contains("anisotropy") ? rd.spectrum(mj.at("anisotropy"), Reader::join(mp, "anisotropy"),
                                                           spectral::SpectrumValues::Signed)
                                             : Spectrum::constant(0.0);
    validate_material(m, rd.input(mp));
    if (mj.contains("emission")) {
      const std::string emp = Reader::join(mp, "emission");
      m.emission = rd.spectrum(mj.at("emission"), emp);
      if (!(m.emission.min_value() >= 0.0) || !std::isfinite(m.emission.max_value())) {
        rd.fail(emp, "must be ≥ 0 and finite at every wavelength (got values in [" + num(m.emission.min_value()) +
                         ", " + num(m.emission.max_value()) + "])");
      }
      if (m.emission.max_value() > kMaxEmission) {
        rd.fail(emp, "must be at most " + num(kMaxEmission) + " at every wavelength (got " + num(m.emission.max_value()) +
                         "); scale the emission layer when relighting instead (--light NAME=SPEC*factor)");
      }
    }
    if (mj.contains("fluorescence")) read_fluorescence(rd, mj.at("fluorescence"), Reader::join(mp, "fluorescence"), m);

    if (mj.contains("density")) {
      const std::string dp = Reader::join(mp, "density");
      const json& d = mj.at("density");
      if (d.is_number()) {
        const double v = rd.number(d, dp);
        if (v < 0.0) rd.fail(dp, "must be ≥ 0 (got " + num(v) + ")");
        if (v > kMaxDensity) rd.fail(dp, "must be at most " + num(kMaxDensity) + " (got " + num(v) + ")");
        rule.density.values = {0.0};
        rule.density.densities = {v};
      } else {
        if (!d.is_array() || d.empty()) {
          rd.fail(dp, "must be a number or [[value, density], …] with at least one point (got " + Reader::describe(d) + ")");
        }
        for (std::size_t k = 0; k < d.size(); ++k) {
          const std::string pp = Reader::index(dp, k);
          if (!d[k].is_array() || d[k].size() != 2) rd.fail(pp, "must be [value, density] (got " + Reader::describe(d[k]) + ")");
          double v = rd.number(d[k][0], Reader::index(pp, 0));
          const double dens = rd.number(d[k][1], Reader::index(pp, 1));
          if (dens < 0.0) rd.fail(Reader::index(pp, 1), "must be ≥ 0 (got " + num(dens) + ")");
          if (dens > kMaxDensity) {
            rd.fail(Reader::index(pp, 1), "must be at most " + num(kMaxDensity) + " (got " + num(dens) + ")");
          }
          if (normalised) v = norm.from_unit(v);
          if (!rule.density.values.empty() && !(v > rule.density.values.back())) {
            rd.fail(Reader::index(pp, 0), "values must be strictly increasing (got " + d[k][0].dump() + " after " +
                                              d[k - 1][0].dump() + ")");
          }
          rule.density.values.push_back(v);
          rule.density.densities.push_back(dens);
        }
      }
    }
    tf.materials.push_back(std::move(m));
    tf.rules.push_back(std::move(rule));
  }
  return tf;
}

TransferFunction read_tf_image(const Reader& rd, const json& j, const ValueNormalisation& norm) {
  const std::string path = "transfer_function";
  rd.expect_object(j, path, {"image", "extinction_scale", "wavelength_range_nm"});
  if (!j.contains("image")) rd.fail(Reader::join(path, "image"), "is required");
  if (!j.contains("extinction_scale")) rd.fail(Reader::join(path, "extinction_scale"), "is required");
  const auto image = rd.file_path(j.at("image"), Reader::join(path, "image"));
  const double scale = rd.positive(j.at("extinction_scale"), Reader::join(path, "extinction_scale"));
  double lo = 400.0;
  double hi = 700.0;
  if (j.contains("wavelength_range_nm")) {
    const std::string wp = Reader::join(path, "wavelength_range_nm");
    const json& w = j.at("wavelength_range_nm");
    if (!w.is_array() || w.size() != 2) rd.fail(wp, "must be [lo, hi] in nm (got " + Reader::describe(w) + ")");
    lo = rd.number(w[0], Reader::index(wp, 0));
    hi = rd.number(w[1], Reader::index(wp, 1));
    if (!(lo < hi) || lo < spectral::BinLayout::kMinNm || hi > spectral::BinLayout::kMaxNm) {
      rd.fail(wp, "must be increasing within [360, 830] nm (got [" + num(lo) + ", " + num(hi) + "])");
    }
  }
  return read_transfer_function_image(image, scale, lo, hi, norm, rd.input(Reader::join(path, "image")));
}

Camera read_camera(const Reader& rd, const json& j) {
  const std::string path = "camera";
  rd.expect_object(j, path, {"type", "position", "look_at", "up", "fov_deg", "ortho_height", "width", "height"});
  Camera c;
  if (j.contains("type")) {
    const std::string tp = Reader::join(path, "type");
    const std::string t = rd.string(j.at("type"), tp);
    if (t == "perspective") c.type = CameraType::Perspective;
    else if (t == "orthographic") c.type = CameraType::Orthographic;
    else rd.fail(tp, "must be \"perspective\" or \"orthographic\" (got \"" + t + "\")");
  }
  // Coordinates beyond 1e12 scene units leave the ray no precision to resolve a volume (and their
  // squares overflow past 1e154): refused rather than rendered as an empty picture.
  constexpr double kMaxCoordinate = 1e12;
  auto vec = [&](const char* key, Eigen::Vector3d& out) {
    if (!j.contains(key)) return;
    const std::string kp = Reader::join(path, key);
    const auto v = rd.vec3(j.at(key), kp);
    for (int i = 0; i < 3; ++i) {
      if (!(std::abs(v[i]) <= kMaxCoordinate)) {
        rd.fail(Reader::index(kp, i), "must be within ±1e12 (got " + num(v[i]) + ")");
      }
    }
    out = Eigen::Vector3d(v[0], v[1], v[2]);
  };
  vec("position", c.position);
  vec("look_at", c.look_at);
  vec("up", c.up);
  const Eigen::Vector3d forward = c.look_at - c.position;
  if (!(forward.norm() > 1e-9)) rd.fail(Reader::join(path, "look_at"), "must differ from position");
  const auto up = unit_direction(c.up);
  if (!up) rd.fail(Reader::join(path, "up"), "must not be the zero vector");
  c.up = *up;
  if (!(forward.normalized().cross(c.up).norm() > 1e-6)) {
    rd.fail(Reader::join(path, "up"), "must not be parallel to the view direction");
  }
  if (j.contains("fov_deg")) {
    const std::string fp = Reader::join(path, "fov_deg");
    c.fov_y_deg = rd.number(j.at("fov_deg"), fp);
    if (!(c.fov_y_deg > 0.0 && c.fov_y_deg < 180.0)) rd.fail(fp, "must be in (0, 180) (got " + num(c.fov_y_deg) + ")");
  }
  if (j.contains("ortho_height")) c.ortho_height = rd.positive(j.at("ortho_height"), Reader::join(path, "ortho_height"));
  if (j.contains("width")) c.width = static_cast<int>(rd.integer(j.at("width"), Reader::join(path, "width"), 1, kMaxImageSide));
  if (j.contains("height")) c.height = static_cast<int>(rd.integer(j.at("height"), Reader::join(path, "height"), 1, kMaxImageSide));
  return c;
}

// A relative csv: path in a light's spec resolves against the scene folder now, so the stored spec
// works from any working directory.
std::string absolute_spec(const std::string& spec, const std::filesystem::path& base) {
  if (spec.rfind("csv:", 0) != 0) return spec;
  const std::size_t star = spec.find('*');
  const std::string file = spec.substr(4, star == std::string::npos ? std::string::npos : star - 4);
  const std::filesystem::path p(file);
  if (p.is_absolute() || base.empty()) return spec;
  return "csv:" + (base / p).string() + (star == std::string::npos ? "" : spec.substr(star));
}

// A light layer's name (a light's, the emission layer's): 1–64 letters, digits, '_' and '-', and not
// a name the spectral EXR reserves ("var" names the variance layers): refused here, before rendering,
// not by the writer after it.
void check_light_name(const Reader& rd, const std::string& name, const std::string& path) {
  if (name.empty() || name.size() > kMaxLightNameLength) {
    rd.fail(path, "must have 1 to " + std::to_string(kMaxLightNameLength) + " characters (got \"" + name + "\")");
  }
  for (char ch : name) {
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-')) {
      rd.fail(path, "may hold only letters, digits, '_' and '-' (got \"" + name + "\")");
    }
  }
  spectral::check_exr_light_name(name, rd.input(path));
}

// An environment-map light's fields: the image, its convention and rotation (docs/scene-format.md,
// "Environment maps"). A square image must say its convention: it is pbrt-v4's equal-area layout as
// often as a latitude–longitude map of an unusual shape, and read as the wrong one every direction
// is wrong.
void read_environment_map(const Reader& rd, const json& lj, const std::string& lp, Light& l) {
  for (const char* key : {"radius", "spot"})
    if (lj.contains(key)) rd.fail(Reader::join(lp, key), "applies to point lights only (this light is an environment map)");
  const std::string ep = Reader::join(lp, "environment");
  if (lj.contains("rotation_deg")) {
    const std::string rp = Reader::join(lp, "rotation_deg");
    l.rotation_deg = rd.number(lj.at("rotation_deg"), rp);
    if (!(std::abs(l.rotation_deg) <= 360.0)) rd.fail(rp, "must be in [-360, 360] (got " + num(l.rotation_deg) + ")");
  }
  const std::string cp = Reader::join(lp, "convention");
  std::optional<EnvironmentConvention> convention;
  if (lj.contains("convention")) convention = parse_environment_convention(rd.string(lj.at("convention"), cp), rd.input(cp));
  l.environment_file = rd.string(lj.at("environment"), ep);
  l.environment_map = std::make_shared<const EnvironmentMap>(EnvironmentMap::load(
      rd.file_path(lj.at("environment"), ep), l.rotation_deg, rd.input(ep), convention.value_or(EnvironmentConvention::Prizma)));
  const EnvironmentMap& map = *l.environment_map;
  if (!convention && map.width() == map.height() && map.width() > 1) {
    rd.fail(cp, "is required for the square image " + l.environment_file + " (" + std::to_string(map.width()) + "×" +
                    std::to_string(map.height()) + "): \"pbrt-equal-area\" for pbrt-v4's equal-area map, or " +
                    "\"prizma\" or \"mitsuba\" for a latitude–longitude map");
  }
}

// A point, sphere or spot light ("position") or an environment map ("environment"), with their
// fields (docs/scene-format.md, "Point, sphere and spot lights", "Environment maps").
void read_point_or_environment_light(const Reader& rd, const json& lj, const std::string& lp, Light& l) {
  const bool point = lj.contains("position");
  const std::string other = point ? "position" : "environment";
  for (const char* key : {"direction", "angular_size_deg"})
    if (lj.contains(key)) rd.fail(Reader::join(lp, key), "does not apply to a light with " + other + " (a light has one of direction, position and environment)");
  if (point) {
    if (lj.contains("environment")) rd.fail(Reader::join(lp, "environment"), "does not apply to a light with position (a light has one of direction, position and environment)");
    for (const char* key : {"rotation_deg", "convention"})
      if (lj.contains(key)) rd.fail(Reader::join(lp, key), "applies to environment-map lights only (this light has a position)");
    const std::string pp = Reader::join(lp, "position");
    const auto p = rd.vec3(lj.at("position"), pp);
    for (int a = 0; a < 3; ++a)
      if (std::abs(p[a]) > kMaxLightCoordinate)
        rd.fail(Reader::index(pp, a), "must be in [-" + num(kMaxLightCoordinate) + ", " + num(kMaxLightCoordinate) + "] (got " + num(p[a]) + ")");
    l.is_point = true;
    l.position = Eigen::Vector3d(p[0], p[1], p[2]);
    if (lj.contains("radius")) {
      const std::string rp = Reader::join(lp, "radius");
      l.radius = rd.number(lj.at("radius"), rp);
      if (!(l.radius >= 0.0 && l.radius <= kMaxLightCoordinate))
        rd.fail(rp, "must be in [0, " + num(kMaxLightCoordinate) + "] (got " + num(l.radius) + ")");
    }
    if (lj.contains("spot")) {
      const std::string sp = Reader::join(lp, "spot");
      const json& sj = lj.at("spot");
      rd.expect_object(sj, sp, {"direction", "cone_deg", "falloff_deg"});
      if (l.radius > 0.0) rd.fail(sp, "a spot light is a point: give radius 0 or no spot");
      const std::string sdp = Reader::join(sp, "direction");
      if (!sj.contains("direction")) rd.fail(sdp, "is required (the spot's axis, away from the light)");
      const auto d = rd.vec3(sj.at("direction"), sdp);
      const auto axis = unit_direction(Eigen::Vector3d(d[0], d[1], d[2]));
      if (!axis) rd.fail(sdp, "must not be [0, 0, 0]");
      l.spot_direction = *axis;
      const std::string cp = Reader::join(sp, "cone_deg");
      if (!sj.contains("cone_deg")) rd.fail(cp, "is required (half-angle of the cone, degrees)");
      l.spot_cone_deg = rd.number(sj.at("cone_deg"), cp);
      if (!(l.spot_cone_deg > 0.0 && l.spot_cone_deg <= 180.0))
        rd.fail(cp, "must be in (0, 180] (got " + num(l.spot_cone_deg) + ")");
      if (sj.contains("falloff_deg")) {
        const std::string fp = Reader::join(sp, "falloff_deg");
        l.spot_falloff_deg = rd.number(sj.at("falloff_deg"), fp);
        if (!(l.spot_falloff_deg >= 0.0 && l.spot_falloff_deg <= l.spot_cone_deg))
          rd.fail(fp, "must be in [0, cone_deg] = [0, " + num(l.spot_cone_deg) + "] (got " + num(l.spot_falloff_deg) + ")");
      }
    }
    return;
  }
  read_environment_map(rd, lj, lp, l);
}

std::vector<Light> read_lights(const Reader& rd, const json& j) {
  const std::string path = "lights";
  if (!j.is_array()) rd.fail(path, "must be an array of lights (got " + Reader::describe(j) + ")");
  if (j.empty()) rd.fail(path, "must have at least one light");
  std::vector<Light> lights;
  std::set<std::string> names;
  for (std::size_t i = 0; i < j.size(); ++i) {
    const std::string lp = Reader::index(path, i);
    const json& lj = j[i];
    rd.expect_object(lj, lp, {"name", "direction", "spectrum", "angular_size_deg", "position", "radius", "spot",
                              "environment", "rotation_deg", "convention"});
    Light l;
    const std::string np = Reader::join(lp, "name");
    if (!lj.contains("name")) rd.fail(np, "is required");
    l.name = rd.string(lj.at("name"), np);
    check_light_name(rd, l.name, np);
    if (!names.insert(l.name).second) rd.fail(np, "duplicate light name \"" + l.name + "\"");
    const std::string dp = Reader::join(lp, "direction");
    if (lj.contains("position") || lj.contains("environment")) {
      read_point_or_environment_light(rd, lj, lp, l);
    } else {
      if (!lj.contains("direction")) rd.fail(dp, "is required ([0, 0, 0] = uniform environment)");
      const auto d = rd.vec3(lj.at("direction"), dp);
      // Only the exact zero vector is the environment (a length of 1e-200 keeps its direction).
      l.direction = unit_direction(Eigen::Vector3d(d[0], d[1], d[2])).value_or(Eigen::Vector3d::Zero());
      if (lj.contains("angular_size_deg")) {
        const std::string ap = Reader::join(lp, "angular_size_deg");
        l.angular_size_deg = rd.number(lj.at("angular_size_deg"), ap);
        if (!(l.angular_size_deg >= 0.0 && l.angular_size_deg < 180.0)) {
          rd.fail(ap, "must be in [0, 180) (got " + num(l.angular_size_deg) + ")");
        }
        if (l.angular_size_deg > 0.0 && l.direction.norm() == 0.0) {
          rd.fail(ap, "applies to directional lights only (this light is the environment)");
        }
      }
      for (const char* key : {"radius", "spot"})
        if (lj.contains(key)) rd.fail(Reader::join(lp, key), "applies to point lights only (give position, not direction)");
      for (const char* key : {"rotation_deg", "convention"})
        if (lj.contains(key)) rd.fail(Reader::join(lp, key), "applies to environment-map lights only (give environment, not direction)");
    }
    if (lj.contains("spectrum")) {
      const std::string sp = Reader::join(lp, "spectrum");
      l.spectrum_spec = rd.string(lj.at("spectrum"), sp);
      rd.spectrum(lj.at("spectrum"), sp);  // validate now, the scale bound of a light included
      spectral::parse_light_spectrum(l.spectrum_spec, {rd.input(sp), rd.base_dir()});
      l.spectrum_spec = absolute_spec(l.spectrum_spec, rd.base_dir());
    }
    lights.push_back(std::move(l));
  }
  return lights;
}

std::uint64_t read_seed(const Reader& rd, const json& j, const std::string& path) {
  if (!j.is_number_integer() || (!j.is_number_unsigned() && j.get<std::int64_t>() < 0)) {
    rd.fail(path, "must be an integer ≥ 0 (got " + Reader::describe(j) + ")");
  }
  return j.get<std::uint64_t>();
}

void read_settings(const Reader& rd, const json& root, RenderSettings& s) {
  if (root.contains("bins")) {
    s.bins = spectral::BinLayout::parse(rd.string(root.at("bins"), "bins"), rd.input("bins"));
    spectral::check_exr_bin_names(s.bins, rd.input("bins"));
  }
  if (root.contains("samples")) s.sample_end = rd.integer(root.at("samples"), "samples", 1, kMaxSamples);
  if (root.contains("seed")) s.seed = read_seed(rd, root.at("seed"), "seed");
  if (root.contains("max_bounces")) s.max_bounces = static_cast<int>(rd.integer(root.at("max_bounces"), "max_bounces", -1, kMaxBounces));
  if (root.contains("wavelength_sampling")) {
    const std::string w = rd.string(root.at("wavelength_sampling"), "wavelength_sampling");
    if (w == "auto") s.wavelength_sampling = WavelengthSampling::Auto;
    else if (w == "spectral-tracking") s.wavelength_sampling = WavelengthSampling::SpectralTracking;
    else if (w == "spectral-mis") s.wavelength_sampling = WavelengthSampling::SpectralMis;
    else if (w == "single") s.wavelength_sampling = WavelengthSampling::Single;
    else rd.fail("wavelength_sampling", "must be \"auto\", \"spectral-tracking\", \"spectral-mis\" or \"single\" (got \"" + w + "\")");
  }
  if (root.contains("sampler"))
    s.sampler = parse_sampler(rd.string(root.at("sampler"), "sampler"), rd.input("sampler"));
  if (root.contains("event_probabilities"))
    s.event_probabilities = parse_event_probabilities(rd.string(root.at("event_probabilities"), "event_probabilities"),
                                                      rd.input("event_probabilities"));
  if (root.contains("target_error")) {
    s.target_error = rd.number(root.at("target_error"), "target_error");
    if (s.target_error < 0.0) rd.fail("target_error", "must be ≥ 0 (got " + num(s.target_error) + ")");
  }
}

// Refuses a medium whose largest extinction × density the trackers cannot step through (float
// overflow makes a majorant infinite and a step zero; a huge optical depth never ends), naming the
// material's extinction (or the transfer function's extinction_scale).
void check_trackable(const Reader& rd, const Medium& med, bool has_materials) {
  // The largest density per material, over the voxels in parallel (a maximum: the same on any thread count).
  using Maxima = std::vector<float>;
  const Maxima max_density = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, med.material.size(), 1 << 16), Maxima(med.materials.size(), 0.0f),
      [&](const tbb::blocked_range<std::size_t>& r, Maxima acc) {
        // By runs of one material (a volume's neighbouring voxels mostly share theirs): the maximum
        // stays in a register instead of a load and store of acc[m] per voxel.
        std::uint16_t run = Medium::kEmpty;
        float run_max = 0.0f;
        const auto flush = [&] {
          if (run != Medium::kEmpty && run < acc.size()) acc[run] = std::max(acc[run], run_max);
        };
        for (std::size_t v = r.begin(); v != r.end(); ++v) {
          const std::uint16_t m = med.material[v];
          if (m != run) {
            flush();
            run = m;
            run_max = 0.0f;
          }
          run_max = std::max(run_max, med.density[v]);
        }
        flush();
        return acc;
      },
      [](Maxima a, const Maxima& b) {
        for (std::size_t m = 0; m < a.size(); ++m) a[m] = std::max(a[m], b[m]);
        return a;
      });
  for (std::size_t m = 0; m < med.materials.size(); ++m) {
    if (!(max_density[m] > 0.0f)) continue;
    const Material& mat = med.materials[m];
    const double sigma_f = mat.fluorescent ? mat.fluorescence.absorption.max_value() : 0.0;
    const double mu = (mat.sigma_t_per_unit.max_value() + sigma_f) * static_cast<double>(max_density[m]);
    if (mu <= kMaxExtinctionPerUnit) continue;
    const std::string field = has_materials ? Reader::join(Reader::index("materials", m), "extinction")
                                            : "transfer_function.extinction_scale";
    rd.fail(field, "extinction × density reaches " + num(mu) + " per unit length (material \"" +
                       med.materials[m].name + "\"); the tracker steps through at most " +
                       num(kMaxExtinctionPerUnit) + " per unit length (the volume's largest side is 1 unit)");
  }
}

// "line L, column C" of byte `offset` of `text` (both counted from 1).
std::string line_column(const std::string& text, std::size_t offset) {
  std::size_t line = 1;
  std::size_t col = 1;
  for (std::size_t i = 0; i < std::min(offset, text.size()); ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(col);
}

// Parses JSON, rejecting duplicate keys, reporting line and column of syntax errors.
json parse_json(const std::string& text, const std::string& file) {
  std::vector<std::set<std::string>> keys;
  std::string duplicate;
  auto cb = [&](int /*depth*/, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::object_start) keys.emplace_back();
    else if (event == json::parse_event_t::object_end && !keys.empty()) keys.pop_back();
    else if (event == json::parse_event_t::key && !keys.empty() && parsed.is_string()) {
      if (!keys.back().insert(parsed.get<std::string>()).second && duplicate.empty()) duplicate = parsed.get<std::string>();
    }
    return true;
  };
  // Depth first: nlohmann::json recurses to print, compare and copy values.
  spectral::check_json_depth(text, file);
  try {
    json j = json::parse(text, cb);
    if (!duplicate.empty()) throw InputError(file, "duplicate key \"" + duplicate + "\"");
    return j;
  } catch (const json::parse_error& e) {
    std::string what = e.what();
    const std::size_t colon = what.find(": ", what.find("parse error"));
    if (colon != std::string::npos) what = what.substr(colon + 2);
    throw InputError(file, "malformed JSON at " + line_column(text, e.byte > 0 ? e.byte - 1 : 0) + ": " + what);
  } catch (const json::out_of_range& e) {
    // A number beyond the range of a double (1e400): nlohmann reports the number, not where it is.
    const std::string what = e.what();
    const std::size_t open = what.find('\''), close = what.rfind('\'');
    const std::string number = open < close ? what.substr(open + 1, close - open - 1) : std::string();
    const std::size_t at = number.empty() ? std::string::npos : text.find(number);
    const std::string where = at == std::string::npos ? std::string() : " at " + line_column(text, at);
    const std::string shown = number.size() > 24 ? number.substr(0, 24) + "..." : number;
    throw InputError(file, "number " + shown + where + " is beyond the range of a double");
  }
}

// The integer range of a scene field, shared by the scene reader and the command-line overrides.
std::pair<std::int64_t, std::int64_t> integer_field_range(const std::string& field) {
  if (field == "camera.width" || field == "camera.height") return {1, kMaxImageSide};
  if (field == "samples") return {1, kMaxSamples};
  if (field == "max_bounces") return {-1, kMaxBounces};
  throw std::logic_error("integer_field_range: unknown field " + field);
}

// A command-line value as JSON (so that "1e9", "8.7" and "-1" are what they are), or InputError.
json override_json(const std::string& text, const std::string& option, const char* expected) {
  spectral::check_json_depth(text, option);
  json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) throw InputError(option, std::string("must be ") + expected + " (got \"" + text + "\")");
  return j;
}

// One "-D KEY=VALUE" applied to the scene's JSON before it is validated. KEY is a field path:
// object keys separated by '.', array elements by index ("lights[1]", "lights.1") or, in arrays of
// named objects (lights, materials), by name ("lights.side"). VALUE is typed by the field it
// replaces: text for a string field, JSON (a number, true, [0, 1, 0], …) otherwise; text that is
// not JSON stays a string, which the scene's own checks then refuse where a number is needed.
// Returns the field's path as the scene reader names it ("lights[0].spectrum").
std::string apply_scene_override(json& root, const SceneOverride& o) {
  const std::string option = "-D " + o.key;
  // Split into segments: "a.b[2].c" → a, b, 2, c.
  const std::string& key = o.key;
  const auto malformed = [&] {
    throw InputError(option, "malformed key (fields separated by '.', elements by index or name: camera.fov_deg, "
                             "lights[0].spectrum, lights.side.spectrum)");
  };
  std::vector<std::string> segments;
  for (std::size_t i = 0; i < key.size();) {
    if (key[i] == '[') {
      const std::size_t close = key.find(']', i);
      if (close == std::string::npos || close == i + 1) malformed();
      segments.push_back(key.substr(i + 1, close - i - 1));
      i = close + 1;
    } else {
      std::size_t end = key.find_first_of(".[", i);
      if (end == std::string::npos) end = key.size();
      if (end == i) malformed();
      segments.push_back(key.substr(i, end - i));
      i = end;
    }
    if (i < key.size()) {
      if (key[i] == '.') {
        if (++i == key.size()) malformed();
      } else if (key[i] != '[') {
        malformed();
      }
    }
  }
  if (segments.empty()) throw InputError("-D", "empty key (expected -D key=value, e.g. -D camera.fov_deg=30)");

  json* node = &root;
  std::string path;  // as Reader names it
  for (std::size_t k = 0; k < segments.size(); ++k) {
    const std::string& seg = segments[k];
    const bool last = k + 1 == segments.size();
    json* next = nullptr;
    if (node->is_array()) {
      std::size_t index = node->size();
      const bool numeric = !seg.empty() && seg.size() <= 9 && std::all_of(seg.begin(), seg.end(), [](char ch) {
        return ch >= '0' && ch <= '9';
      });
      if (numeric) {
        index = static_cast<std::size_t>(std::stoul(seg));
      } else {
        for (std::size_t i = 0; i < node->size(); ++i) {
          const json& e = (*node)[i];
          if (e.is_object() && e.contains("name") && e.at("name").is_string() && e.at("name").get<std::string>() == seg) {
            index = i;
            break;
          }
        }
      }
      if (index >= node->size()) {
        std::string names;
        for (const json& e : *node)
          if (e.is_object() && e.contains("name") && e.at("name").is_string())
            names += (names.empty() ? "" : ", ") + e.at("name").get<std::string>();
        throw InputError(option, (path.empty() ? std::string("the scene") : path) + " has no element " +
                                     (numeric ? seg : "named \"" + seg + "\"") + " (" +
                                     std::to_string(node->size()) + " elements" +
                                     (names.empty() ? std::string() : ": " + names) + ")");
      }
      path = Reader::index(path, index);
      next = &(*node)[index];
    } else {
      if (node->is_null()) *node = json::object();  // a section the scene leaves out: "-D camera.fov_deg=30"
      if (!node->is_object())
        throw InputError(option, path + " is " + std::string(node->type_name()) + ", not an object with fields");
      path = Reader::join(path, seg);
      next = &(*node)[seg];  // created (null) when absent
    }
    if (last) {
      json value;
      const bool string_field = next->is_string();
      if (!string_field) {
        spectral::check_json_depth(o.value, option);
        value = json::parse(o.value, nullptr, /*allow_exceptions=*/false);
      }
      if (string_field || value.is_discarded()) {
        // A JSON string literal ("\"D65\"") is taken as its text, other text as it is.
        const json quoted = json::parse(o.value, nullptr, false);
        value = !quoted.is_discarded() && quoted.is_string() ? quoted : json(o.value);
      }
      *next = std::move(value);
    }
    node = next;
  }
  return path;
}

}  // namespace

SceneOverride parse_scene_override(const std::string& text) {
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("-D " + text, "expected KEY=VALUE, e.g. -D camera.fov_deg=30 (KEY a field path of the scene)");
  return SceneOverride{text.substr(0, eq), text.substr(eq + 1)};
}

std::int64_t scene_integer_override(const std::string& text, const std::string& field, const std::string& option) {
  const auto [lo, hi] = integer_field_range(field);
  const json j = override_json(text, option, "an integer");
  return Reader("", {}).integer(j, option, lo, hi);
}

std::uint64_t scene_seed_override(const std::string& text, const std::string& option) {
  const json j = override_json(text, option, "an integer ≥ 0");
  return read_seed(Reader("", {}), j, option);
}

namespace {

// The scene in `text`, named `file` in messages; `path` is its source (relative paths resolve in its
// folder; the default output is beside it).
Scene scene_from_text(const std::string& text, const std::string& file, const std::filesystem::path& path,
                      const std::vector<SceneOverride>& overrides) {
  json root = parse_json(text, file);
  std::vector<std::string> overridden;
  if (!overrides.empty() && !root.is_object()) throw InputError(file, "must be an object (the scene) for -D");
  for (const SceneOverride& o : overrides) {
    const std::string field = apply_scene_override(root, o);
    if (std::find(overridden.begin(), overridden.end(), field) != overridden.end())
      throw InputError("-D " + o.key, "is given twice");
    overridden.push_back(field);
  }
  const Reader rd(file, path.parent_path(), overridden);
  if (root.contains("normalisation") && root.contains("normalization"))
    rd.fail("normalization", "give normalisation or normalization (the same field), not both");
  rd.expect_object(root, "",
                   {"description", "volume", "normalisation", "normalization", "materials", "transfer_function", "camera", "lights",
                    "bins", "samples", "seed", "max_bounces", "wavelength_sampling", "sampler", "event_probabilities", "target_error", "output",
                    "emission_light"});
  if (root.contains("description")) rd.string(root.at("description"), "description");
  if (!root.contains("volume")) rd.fail("volume", "is required");
  if (!root.contains("lights")) rd.fail("lights", "is required (at least one light)");
  const bool has_materials = root.contains("materials");
  const bool has_tf = root.contains("transfer_function");
  if (has_materials == has_tf) {
    rd.fail(has_materials ? "transfer_function" : "materials",
            has_materials ? "give either materials or transfer_function, not both"
                          : "is required (or a transfer_function image)");
  }

  Scene scene;
  scene.source = path;
  // Validate the cheap parts first so a typo is reported before a large volume is read.
  scene.lights = read_lights(rd, root.at("lights"));
  if (root.contains("camera")) scene.camera = read_camera(rd, root.at("camera"));
  read_settings(rd, root, scene.settings);
  scene.output = path.parent_path() / (path.stem().string() + ".exr");
  if (root.contains("output")) scene.output = rd.file_path(root.at("output"), "output");

  const Interpolation interpolation = read_interpolation(rd, root.at("volume"));
  std::vector<ClipPlane> clip = read_clip(rd, root.at("volume"));
  Volume vol = read_volume(rd, root.at("volume"));

  // Hash: scene text, volume values, the materials' spectra (which csv files or images may supply).
  // FNV-1a takes one multiply per byte in sequence (1.5 ms for a 64³ volume), so the voxels are
  // hashed in a task beside the classification below; the value is the same on any thread count.
  Fnv1a h;
  h.add(text.data(), text.size());
  for (const SceneOverride& o : overrides) {  // a render with -D is not the file's render (--resume checks)
    const std::string d = "\n-D " + o.key + "=" + o.value;
    h.add(d.data(), d.size());
  }
  h.add(vol.dims.data(), sizeof vol.dims);
  h.add(vol.spacing.data(), sizeof vol.spacing);
  tbb::task_group hashing;  // waited for below (or cancelled and waited for if an error unwinds)
  hashing.run([&h, &vol] { h.add(vol.values.data(), vol.values.size() * sizeof(float)); });

  const ValueNormalisation norm = read_normalisation(rd, root, vol);
  const TransferFunction tf = has_materials ? read_materials(rd, root.at("materials"), norm)
                                            : read_tf_image(rd, root.at("transfer_function"), norm);
  scene.medium = build_medium(vol, tf, rd.input("volume"), interpolation);
  scene.medium.clip = std::move(clip);
  scene.volume_note = vol.orientation;
  scene.warnings = vol.warnings;
  check_trackable(rd, scene.medium, has_materials);

  // Emission: one light layer for every emitting material, only when some material emits (a scene
  // without emission renders exactly as before).
  std::string emission_name = "emission";
  if (root.contains("emission_light")) {
    emission_name = rd.string(root.at("emission_light"), "emission_light");
    check_light_name(rd, emission_name, "emission_light");
  }
  const bool emits = std::any_of(scene.medium.materials.begin(), scene.medium.materials.end(),
                                 [](const Material& m) { return m.emission.max_value() > 0.0; });
  if (emits) {
    for (const Light& l : scene.lights)
      if (l.name == emission_name)
        rd.fail("emission_light", "the emission layer \"" + emission_name + "\" has the name of a light (name it with emission_light)");
    Light e;
    e.name = emission_name;
    e.emission = true;
    e.spectrum_spec = "E";
    scene.lights.push_back(std::move(e));
  }

  hashing.wait();
  for (const Material& m : scene.medium.materials) {
    h.add(m.name.data(), m.name.size());
    h.add_spectrum(m.albedo);
    h.add_spectrum(m.sigma_t_per_unit);
    h.add_spectrum(m.anisotropy);
    if (m.emission.max_value() > 0.0) h.add_spectrum(m.emission);  // hashes of scenes without emission unchanged
    if (m.fluorescent) {  // likewise without fluorescence
      h.add_spectrum(m.fluorescence.absorption);
      h.add_spectrum(m.fluorescence.emission);
      h.add(&m.fluorescence.quantum_yield, sizeof m.fluorescence.quantum_yield);
    }
  }
  for (const Light& l : scene.lights)  // environment images (the scene text holds only their names)
    if (l.environment_map) h.add(l.environment_map->values().data(), l.environment_map->values().size() * sizeof(float));
  scene.hash = h.hex();
  return scene;
}

}  // namespace

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
    const json root = parse_json(buffer.str(), file);
    const Reader rd(file, path.parent_path());
    if (!root.is_object() || !root.contains("volume")) rd.fail("volume", "is required");
    out.volume = read_volume(rd, root.at("volume"));
    out.from_scene = true;
    out.normalisation_given = (root.contains("normalisation") && root.at("normalisation").is_object()) ||
                              (root.contains("normalization") && root.at("normalization").is_object());
    out.normalisation = read_normalisation(rd, root, out.volume);
    if (root.contains("materials")) out.transfer = read_materials(rd, root.at("materials"), out.normalisation);
    else if (root.contains("transfer_function")) out.transfer = read_tf_image(rd, root.at("transfer_function"), out.normalisation);
    return out;
  }
  // A volume file: the "volume" a scene would give for it.
  const char* type = ends(".nii") || ends(".nii.gz") ? "nifti" : ends(".raw") ? "raw" : ends(".vdb") ? "vdb" : nullptr;
  if (type == nullptr) {
    throw InputError(file, "not a scene or volume file this can inspect (known: .json, .nii, .nii.gz, .raw, .vdb)");
  }
  const Reader rd("", std::filesystem::path());  // the path as given: the loaders' messages name it so
  out.volume = read_volume(rd, json{{"type", type}, {"path", file}});
  out.normalisation = auto_normalisation(out.volume);
  return out;
}

Scene load_scene_text(const std::string& text, const std::string& input, const std::filesystem::path& base_dir,
                      const std::vector<SceneOverride>& overrides) {
  return scene_from_text(text, input, base_dir / input, overrides);
}

}  // namespace prizma::render
