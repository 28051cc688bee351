#include "prizma/spectral/light_spectrum.h"

#include <charconv>
#include <cmath>
#include <string>
#include <utility>

#include "prizma/spectral/error.h"
#include "text_util.h"

namespace prizma::spectral {

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// Parses the whole of s as a number; false when it is not one.
bool parse_number(std::string_view s, double& value) {
  s = trim(s);
  if (s.empty()) return false;
  const char* end = s.data() + s.size();
  const auto [ptr, ec] = std::from_chars(s.data(), end, value);
  return ec == std::errc() && ptr == end;
}

}  // namespace

namespace {

// Peels trailing "*<number>" factors off `text`: the bare spectrum's text and the factors' product.
// The normalisation applies to the bare spectrum, the scale after it (design.md: scale 1 means a
// white under the light has Y = 1).
std::pair<std::string_view, double> split_scale(std::string_view text, const SpecContext& ctx) {
  std::string_view base = text;
  double scale = 1.0;
  for (auto star = base.rfind('*'); star != std::string_view::npos; star = base.rfind('*')) {
    double factor = 0.0;
    if (!parse_number(base.substr(star + 1), factor)) break;
    if (!std::isfinite(factor) || factor < 0.0) {
      throw InputError(ctx.input, "light scale must be finite and non-negative: \"" + std::string(text) + "\"");
    }
    scale *= factor;
    base = trim(base.substr(0, star));
  }
  if (!(scale <= kMaxLightScale)) {
    throw InputError(ctx.input, "light scale " + detail::format_double(scale) + " in \"" + std::string(text) +
                                    "\" is above " + detail::format_double(kMaxLightScale) +
                                    ", the most a relight can apply without overflowing (--exposure adds up to 64 stops)");
  }
  return {base, scale};
}

}  // namespace

LightSpectrum parse_light_spectrum(std::string_view text, const SpecContext& ctx) {
  LightSpectrum out;
  out.text = std::string(trim(text));
  if (out.text.empty()) throw InputError(ctx.input, "empty light spec");
  const auto [base, scale] = split_scale(out.text, ctx);
  out.scaled = base.size() != out.text.size() || base == "off";
  if (base == "off") {
    out.off = true;
    out.scale = 0.0;
    return out;
  }
  out.scale = scale;
  out.spectrum = parse_spectrum(base, ctx);
  if (out.scale == 0.0) out.off = true;
  return out;
}

double light_spec_scale(std::string_view text, const SpecContext& ctx) {
  const auto [base, scale] = split_scale(trim(text), ctx);
  return base == "off" ? 0.0 : scale;
}

LightSpectrum at_light_scale(const LightSpectrum& given, double current_scale) {
  if (given.scaled) return given;
  LightSpectrum out = given;
  out.scaled = true;
  if (!(current_scale > 0.0)) {
    out.text = "off";
    out.scale = 0.0;
    out.off = true;
  } else if (current_scale != 1.0) {
    out.text += "*" + detail::format_double(current_scale);
    out.scale = current_scale;
  }
  return out;
}

Eigen::Matrix<double, 3, Eigen::Dynamic> relight_weights(const ColorMatching& cmf, const LightSpectrum& light,
                                                          const BinLayout& bins, LightUnits units) {
  if (light.off) return Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, bins.size());
  return relight_weights(cmf, light.spectrum, bins, units) * light.scale;
}

}  // namespace prizma::spectral
