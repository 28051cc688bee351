// The scene's lights (docs/scene-format.md, "Lights"): directional and environment lights, point,
// sphere and spot lights, environment maps, each with a name (its layer in the spectral EXR) and a
// default spectrum; and the emission layer of emitting materials.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <memory>
#include <set>

#include "prizma/spectral/light_spectrum.h"
#include "prizma/spectral/spectral_exr.h"
#include "scene_reader.h"

namespace prizma::render::scene_file {

namespace {

constexpr std::size_t kMaxLightNameLength = 64;
// Point-light positions and radii: |coordinate| ≤ this (the volume's largest side is 1 unit).
constexpr double kMaxLightCoordinate = 1e6;

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

// A point light's "spot": {"direction": axis, "cone_deg": half-angle, "falloff_deg": smooth edge}.
void read_spot(const Reader& rd, const json& sj, const std::string& sp, Light& l) {
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

// A point, sphere or spot light ("position"), with its fields (docs/scene-format.md, "Point, sphere
// and spot lights").
void read_point_light(const Reader& rd, const json& lj, const std::string& lp, Light& l) {
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
  if (lj.contains("spot")) read_spot(rd, lj.at("spot"), Reader::join(lp, "spot"), l);
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

// A directional light, or the uniform environment (direction [0, 0, 0]).
void read_directional_light(const Reader& rd, const json& lj, const std::string& lp, Light& l) {
  const std::string dp = Reader::join(lp, "direction");
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

}  // namespace

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
    if (lj.contains("position") || lj.contains("environment")) {
      const std::string other = lj.contains("position") ? "position" : "environment";
      for (const char* key : {"direction", "angular_size_deg"})
        if (lj.contains(key)) rd.fail(Reader::join(lp, key), "does not apply to a light with " + other + " (a light has one of direction, position and environment)");
      if (lj.contains("position"))
        read_point_light(rd, lj, lp, l);
      else
        read_environment_map(rd, lj, lp, l);
    } else {
      read_directional_light(rd, lj, lp, l);
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

void add_emission_light(const Reader& rd, const json& root, Scene& scene) {
  std::string emission_name = "emission";
  if (root.contains("emission_light")) {
    emission_name = rd.string(root.at("emission_light"), "emission_light");
    check_light_name(rd, emission_name, "emission_light");
  }
  const bool emits = std::any_of(scene.medium.materials.begin(), scene.medium.materials.end(),
                                 [](const Material& m) { return m.emission.max_value() > 0.0; });
  if (!emits) return;  // a scene without emission renders exactly as before
  for (const Light& l : scene.lights)
    if (l.name == emission_name)
      rd.fail("emission_light", "the emission layer \"" + emission_name + "\" has the name of a light (name it with emission_light)");
  Light e;
  e.name = emission_name;
  e.emission = true;
  e.spectrum_spec = "E";
  scene.lights.push_back(std::move(e));
}

}  // namespace prizma::render::scene_file
