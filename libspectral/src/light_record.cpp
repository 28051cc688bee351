// prizma:lights as typed records: the one parser and the one writer of its JSON.
#include "prizma/spectral/light_record.h"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "prizma/spectral/error.h"
#include "prizma/spectral/input_file.h"

namespace prizma::spectral {
namespace {

using json = nlohmann::json;

// Reads one record's fields, each checked for its type; `where` names the entry in messages.
class RecordReader {
 public:
  RecordReader(const json& object, std::string where) : m_object(object), m_where(std::move(where)) {}

  const json* field(const char* key, bool (json::*is_type)() const noexcept, const char* expected) const {
    const auto it = m_object.find(key);
    if (it == m_object.end()) return nullptr;
    if (!((*it).*is_type)()) throw InputError(m_where, std::string("\"") + key + "\" must be " + expected);
    return &*it;
  }
  std::optional<std::string> string(const char* key) const {
    const json* v = field(key, &json::is_string, "a string");
    return v ? std::optional<std::string>(v->get<std::string>()) : std::nullopt;
  }
  std::optional<double> number(const char* key) const {
    const json* v = field(key, &json::is_number, "a number");
    return v ? std::optional<double>(v->get<double>()) : std::nullopt;
  }
  bool boolean(const char* key) const {
    const json* v = field(key, &json::is_boolean, "true or false");
    return v != nullptr && v->get<bool>();
  }
  std::optional<std::array<double, 3>> vec3(const char* key) const { return vec3_of(field(key, &json::is_array, "an array of 3 numbers"), key); }
  const json* object(const char* key) const { return field(key, &json::is_object, "an object"); }

  std::optional<std::array<double, 3>> vec3_of(const json* v, const char* key) const {
    if (v == nullptr) return std::nullopt;
    if (v->size() != 3 || !std::all_of(v->begin(), v->end(), [](const json& x) { return x.is_number(); })) {
      throw InputError(m_where, std::string("\"") + key + "\" must be an array of 3 numbers");
    }
    return std::array<double, 3>{(*v)[0].get<double>(), (*v)[1].get<double>(), (*v)[2].get<double>()};
  }
  const std::string& where() const { return m_where; }

 private:
  const json& m_object;
  std::string m_where;
};

LightRecord read_record(const json& entry, const std::string& where) {
  if (!entry.is_object()) throw InputError(where, "is not an object");
  const RecordReader r(entry, where);
  LightRecord rec;
  const std::optional<std::string> name = r.string("name");
  if (!name) throw InputError(where, "has no \"name\"");
  rec.name = *name;
  rec.spectrum = r.string("spectrum").value_or("");
  rec.direction = r.vec3("direction");
  rec.angular_size_deg = r.number("angularSizeDeg");
  rec.emission = r.boolean("emission");
  rec.position = r.vec3("position");
  rec.radius = r.number("radius").value_or(0.0);
  if (const json* spot = r.object("spot")) {
    const RecordReader s(*spot, where + ".spot");
    SpotRecord sr;
    if (const auto d = s.vec3("direction")) sr.direction = *d;
    sr.cone_deg = s.number("coneDeg").value_or(0.0);
    sr.falloff_deg = s.number("falloffDeg").value_or(0.0);
    rec.spot = sr;
  }
  rec.environment = r.string("environment");
  rec.rotation_deg = r.number("rotationDeg").value_or(0.0);
  return rec;
}

json array3(const std::array<double, 3>& v) { return json::array({v[0], v[1], v[2]}); }

}  // namespace

std::vector<LightRecord> parse_light_records(std::string_view text, const std::string& input) {
  check_json_depth(text, input);
  const json parsed = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (parsed.is_discarded()) throw InputError(input, "is not valid JSON");
  if (!parsed.is_array()) throw InputError(input, "is not a JSON array of lights");
  std::vector<LightRecord> out;
  for (std::size_t k = 0; k < parsed.size(); ++k) out.push_back(read_record(parsed[k], input + "[" + std::to_string(k) + "]"));
  return out;
}

std::string light_records_json(const std::vector<LightRecord>& records) {
  json arr = json::array();
  for (const LightRecord& r : records) {
    json j = {{"name", r.name}};  // an object's keys print in alphabetical order
    if (!r.spectrum.empty()) j["spectrum"] = r.spectrum;
    if (r.direction) j["direction"] = array3(*r.direction);
    if (r.angular_size_deg) j["angularSizeDeg"] = *r.angular_size_deg;
    if (r.emission) j["emission"] = true;
    if (r.position) j["position"] = array3(*r.position);
    if (r.radius > 0.0) j["radius"] = r.radius;
    if (r.spot) {
      j["spot"] = {{"direction", array3(r.spot->direction)}, {"coneDeg", r.spot->cone_deg}, {"falloffDeg", r.spot->falloff_deg}};
    }
    if (r.environment) {
      j["environment"] = *r.environment;
      j["rotationDeg"] = r.rotation_deg;
    }
    arr.push_back(std::move(j));
  }
  return arr.dump();
}

LightRecord light_record(std::string name, std::string spectrum) {
  LightRecord r;
  r.name = std::move(name);
  r.spectrum = std::move(spectrum);
  return r;
}

std::vector<LightRecord> light_records_for(const std::vector<std::string>& layer_names) {
  std::vector<LightRecord> out;
  for (const auto& n : layer_names) out.push_back(light_record(n));
  return out;
}

void check_light_records(const std::vector<LightRecord>& records, const std::vector<std::string>& layer_names,
                         const std::string& input) {
  for (std::size_t k = 0; k < records.size(); ++k) {
    for (std::size_t j = 0; j < k; ++j) {
      if (records[j].name == records[k].name) throw InputError(input, "prizma:lights records light \"" + records[k].name + "\" twice");
    }
  }
  if (records.size() < 2) return;
  for (const LightRecord& r : records) {
    if (std::find(layer_names.begin(), layer_names.end(), r.name) != layer_names.end()) continue;
    std::string known;
    for (const auto& n : layer_names) known += (known.empty() ? "" : ", ") + n;
    throw InputError(input, "prizma:lights announces light \"" + r.name + "\" but the file has no layer for it (layers: " +
                                known + ")");
  }
}

std::string default_spectrum(const std::vector<LightRecord>& records, std::string_view layer, std::size_t layer_count) {
  for (const LightRecord& r : records) {
    if (r.spectrum.empty()) continue;
    if (r.name == layer || (layer_count == 1 && records.size() == 1)) return r.spectrum;
  }
  return "D65";
}

}  // namespace prizma::spectral
