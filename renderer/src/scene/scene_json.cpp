// The scene file's JSON: parsing (duplicate keys refused, errors with line and column) and the
// command-line overrides -D KEY=VALUE applied to it before it is read (docs/renderer.md).
#include <algorithm>
#include <set>

#include "prizma/spectral/error.h"
#include "prizma/spectral/input_file.h"
#include "scene_reader.h"

namespace prizma::render::scene_file {

namespace {

using spectral::InputError;

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

// A -D key split into its segments: "a.b[2].c" → a, b, 2, c.
std::vector<std::string> split_override_key(const std::string& key, const std::string& option) {
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
  return segments;
}

// The element of array `node` that segment `seg` names: an index, or the element whose "name" is seg.
std::size_t array_element(const json& node, const std::string& seg, const std::string& path, const std::string& option) {
  std::size_t index = node.size();
  const bool numeric = !seg.empty() && seg.size() <= 9 && std::all_of(seg.begin(), seg.end(), [](char ch) {
    return ch >= '0' && ch <= '9';
  });
  if (numeric) {
    index = static_cast<std::size_t>(std::stoul(seg));
  } else {
    for (std::size_t i = 0; i < node.size(); ++i) {
      const json& e = node[i];
      if (e.is_object() && e.contains("name") && e.at("name").is_string() && e.at("name").get<std::string>() == seg) {
        index = i;
        break;
      }
    }
  }
  if (index < node.size()) return index;
  std::string names;
  for (const json& e : node)
    if (e.is_object() && e.contains("name") && e.at("name").is_string())
      names += (names.empty() ? "" : ", ") + e.at("name").get<std::string>();
  throw InputError(option, (path.empty() ? std::string("the scene") : path) + " has no element " +
                               (numeric ? seg : "named \"" + seg + "\"") + " (" + std::to_string(node.size()) +
                               " elements" + (names.empty() ? std::string() : ": " + names) + ")");
}

// The value of "-D KEY=VALUE" for the field `field` it replaces: text for a string field, JSON
// otherwise (text that is not JSON stays a string, which the scene's own checks then refuse where a
// number is needed); a JSON string literal ("\"D65\"") is taken as its text.
json override_value(const json& field, const SceneOverride& o, const std::string& option) {
  json value;
  const bool string_field = field.is_string();
  if (!string_field) {
    spectral::check_json_depth(o.value, option);
    value = json::parse(o.value, nullptr, /*allow_exceptions=*/false);
  }
  if (string_field || value.is_discarded()) {
    const json quoted = json::parse(o.value, nullptr, false);
    value = !quoted.is_discarded() && quoted.is_string() ? quoted : json(o.value);
  }
  return value;
}

}  // namespace

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

json override_json(const std::string& text, const std::string& option, const char* expected) {
  spectral::check_json_depth(text, option);
  json j = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) throw InputError(option, std::string("must be ") + expected + " (got \"" + text + "\")");
  return j;
}

// KEY is a field path: object keys separated by '.', array elements by index ("lights[1]",
// "lights.1") or, in arrays of named objects (lights, materials), by name ("lights.side").
std::string apply_scene_override(json& root, const SceneOverride& o) {
  const std::string option = "-D " + o.key;
  const std::vector<std::string> segments = split_override_key(o.key, option);
  json* node = &root;
  std::string path;  // as Reader names it
  for (std::size_t k = 0; k < segments.size(); ++k) {
    const std::string& seg = segments[k];
    json* next = nullptr;
    if (node->is_array()) {
      const std::size_t index = array_element(*node, seg, path, option);
      path = Reader::index(path, index);
      next = &(*node)[index];
    } else {
      if (node->is_null()) *node = json::object();  // a section the scene leaves out: "-D camera.fov_deg=30"
      if (!node->is_object())
        throw InputError(option, path + " is " + std::string(node->type_name()) + ", not an object with fields");
      path = Reader::join(path, seg);
      next = &(*node)[seg];  // created (null) when absent
    }
    if (k + 1 == segments.size()) *next = override_value(*next, o, option);
    node = next;
  }
  return path;
}

}  // namespace prizma::render::scene_file
