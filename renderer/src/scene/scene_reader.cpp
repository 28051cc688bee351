// The checks every section of the scene file shares (scene_reader.h).
#include "scene_reader.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "prizma/spectral/error.h"

namespace prizma::render::scene_file {

using spectral::InputError;
using spectral::Spectrum;

std::string num(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

std::optional<Eigen::Vector3d> unit_direction(const Eigen::Vector3d& v, double* along) {
  const double largest = v.cwiseAbs().maxCoeff();
  if (!(largest > 0.0)) return std::nullopt;
  const Eigen::Vector3d scaled = v / largest;
  const double norm = scaled.norm();
  if (along != nullptr) *along = *along / largest / norm;
  return Eigen::Vector3d(scaled / norm);
}

std::string Reader::input(const std::string& path) const {
  if (m_file.empty()) return path;  // a command-line option
  // A field set (or inside a value set) by -D KEY=VALUE is named as the option that set it.
  for (const std::string& o : m_overridden) {
    if (path == o || (path.size() > o.size() && path.compare(0, o.size(), o) == 0 &&
                      (path[o.size()] == '.' || path[o.size()] == '[')))
      return "-D " + path;
  }
  return path.empty() ? m_file : m_file + ": " + path;
}

void Reader::fail(const std::string& path, const std::string& reason) const { throw InputError(input(path), reason); }

std::string Reader::describe(const json& j) {
  std::string text = j.dump();
  if (text.size() > 40) text = text.substr(0, 37) + "...";
  return std::string(j.type_name()) + " " + text;
}

void Reader::expect_object(const json& j, const std::string& path, std::initializer_list<const char*> known) const {
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

double Reader::number(const json& j, const std::string& path) const {
  if (!j.is_number()) fail(path, "must be a number (got " + describe(j) + ")");
  const double v = j.get<double>();
  if (!std::isfinite(v)) fail(path, "must be finite");
  return v;
}

std::int64_t Reader::integer(const json& j, const std::string& path, std::int64_t lo, std::int64_t hi) const {
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

std::string Reader::string(const json& j, const std::string& path) const {
  if (!j.is_string()) fail(path, "must be a string (got " + describe(j) + ")");
  return j.get<std::string>();
}

std::array<double, 3> Reader::vec3(const json& j, const std::string& path) const {
  if (!j.is_array() || j.size() != 3) fail(path, "must be an array of 3 numbers (got " + describe(j) + ")");
  return {number(j[0], index(path, 0)), number(j[1], index(path, 1)), number(j[2], index(path, 2))};
}

double Reader::positive(const json& j, const std::string& path) const {
  const double v = number(j, path);
  if (!(v > 0.0)) fail(path, "must be > 0 (got " + num(v) + ")");
  return v;
}

std::filesystem::path Reader::file_path(const json& j, const std::string& path) const {
  const std::string s = string(j, path);
  if (s.empty()) fail(path, "must not be empty");
  const std::filesystem::path p(s);
  return p.is_absolute() ? p : m_base / p;
}

Spectrum Reader::spectrum(const json& j, const std::string& path, spectral::SpectrumValues values) const {
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

}  // namespace prizma::render::scene_file
