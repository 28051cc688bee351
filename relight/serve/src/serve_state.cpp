#include "prizma/relight/serve_state.h"

#include <charconv>
#include <cmath>
#include <cstdio>

#include "prizma/spectral/colour_matching.h"
#include "prizma/spectral/error.h"

namespace prizma::relight {

namespace {

using spectral::InputError;

constexpr const char* kLightPrefix = "light.";

double parse_number(const std::string& key, const std::string& value) {
  double v = 0.0;
  const char* end = value.data() + value.size();
  const auto [ptr, ec] = std::from_chars(value.data(), end, v);
  if (value.empty() || ec != std::errc() || ptr != end || !std::isfinite(v)) {
    throw InputError("state: " + key, "not a number: \"" + value + "\"");
  }
  return v;
}

bool parse_flag(const std::string& key, const std::string& value) {
  if (value == "1" || value == "on" || value == "true") return true;
  if (value == "0" || value == "off" || value == "false") return false;
  throw InputError("state: " + key, "expected 0 or 1, not \"" + value + "\"");
}

}  // namespace

std::string observer_state_name(spectral::Observer observer) {
  switch (observer) {
    case spectral::Observer::Cie1931_2deg: return "1931";
    case spectral::Observer::Cie1964_10deg: return "1964";
    case spectral::Observer::Cie2012_2deg: return "2012-2";
    case spectral::Observer::Cie2012_10deg: return "2012-10";
  }
  return "1931";
}

std::string url_encode(const std::string& text) {
  std::string out;
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if ((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-' || c == '_' ||
        c == '.' || c == '~' || c == '*' || c == ':') {
      out += ch;
    } else {
      char buf[4];
      std::snprintf(buf, sizeof buf, "%%%02X", c);
      out += buf;
    }
  }
  return out;
}

RelightSettings settings_from_state(const StateParams& params, const RelightSession& session,
                                    const RelightSettings& base) {
  RelightSettings s = base;
  for (const auto& [key, value] : params) {
    if (key.rfind(kLightPrefix, 0) == 0) {
      const std::string name = key.substr(std::char_traits<char>::length(kLightPrefix));
      const auto l = static_cast<std::size_t>(session.light_index(name, "state: " + key));
      const LightSpec& fallback = session.default_lights()[l];
      if (value == base.lights[l].text) {
        s.lights[l] = base.lights[l];
      } else if (value == fallback.text) {
        s.lights[l] = fallback;
      } else if (value.find("csv:") != std::string::npos) {
        throw InputError("state: " + key, "csv: spectra are not read from the page (give them on the command line)");
      } else {
        s.lights[l] = parse_light_spec(value, {"state: " + key, {}});
      }
    } else if (key == "exposure") {
      s.relight.exposure_ev = parse_number(key, value);
    } else if (key == "cmf") {
      s.relight.cmf = spectral::parse_observer(value, "state: cmf");
    } else if (key == "display") {
      s.output.display.display = value;
      s.output.display.view.clear();
    } else if (key == "adapt") {
      s.relight.adapt_to_d65 = parse_flag(key, value);
    } else {
      throw InputError("state: " + key, "unknown key (known: light.NAME, exposure, cmf, display, adapt)");
    }
  }
  RelightSettingNames names;  // the page sets no bit depth
  names.exposure = "state: exposure";
  s.validate(names);
  return s;
}

std::string state_string(const RelightSettings& settings, const RelightSession& session) {
  std::string out;
  for (std::size_t l = 0; l < session.light_names().size(); ++l) {
    if (!out.empty()) out += '&';
    out += kLightPrefix + url_encode(session.light_names()[l]) + "=" + url_encode(settings.lights[l].text);
  }
  // Shortest text that reads back as the same double.
  char ev[32];
  const auto result = std::to_chars(ev, ev + sizeof ev, settings.relight.exposure_ev);
  out += "&exposure=" + std::string(ev, result.ptr);
  out += "&cmf=" + observer_state_name(settings.relight.cmf);
  out += "&display=" + url_encode(settings.output.display.display);
  out += std::string("&adapt=") + (settings.relight.adapt_to_d65 ? "1" : "0");
  return out;
}

}  // namespace prizma::relight
