// The scene's volume section (docs/scene-format.md, "Volume"): its source (procedural, raw, NIfTI,
// OpenVDB), voxel spacing, clip planes and interpolation, and the value normalisation that the
// materials' "normalised" ranges read.
#include <algorithm>
#include <array>

#include "scene_reader.h"

namespace prizma::render::scene_file {

namespace {

constexpr int kDefaultResolution = 128;

// volume.type "procedural": one of procedural_volume_names() at a resolution.
Volume read_procedural(const Reader& rd, const json& j, const std::string& path) {
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
  return make_procedural_volume(name, res);
}

// volume.type "raw": the file, its dims, voxel type and byte order (volume_raw.cpp reads it).
Volume read_raw(const Reader& rd, const json& j, const std::string& path, const std::array<double, 3>& spacing) {
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
  return load_raw_volume(spec);
}

}  // namespace

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
    vol = read_procedural(rd, j, path);
  } else if (type == "raw") {
    vol = read_raw(rd, j, path, spacing);
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

}  // namespace prizma::render::scene_file
