#include "prizma/spectral/light_spectrum.h"

#include <charconv>
#include <cmath>
#include <string>

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

LightSpectrum parse_light_spectrum(std::string_view text, const SpecContext& ctx) {
  LightSpectrum out;
  out.text = std::string(trim(text));
  if (out.text.empty()) throw InputError(ctx.input, "empty light spec");
  if (out.text == "off") {
    out.off = true;
    out.scale = 0.0;
    return out;
  }
  // Peel trailing "*<number>" factors off: the normalisation applies to the bare spectrum, the
  // scale after it (design.md: scale 1 means a white under the light has Y = 1).
  std::string_view base = out.text;
  for (auto star = base.rfind('*'); star != std::string_view::npos; star = base.rfind('*')) {
    double factor = 0.0;
    if (!parse_number(base.substr(star + 1), factor)) break;
    if (!std::isfinite(factor) || factor < 0.0) {
      throw InputError(ctx.input, "light scale must be finite and non-negative: \"" + out.text + "\"");
    }
    out.scale *= factor;
    base = trim(base.substr(0, star));
  }
  if (!(out.scale <= kMaxLightScale)) {
    throw InputError(ctx.input, "light scale " + detail::format_double(out.scale) + " in \"" + out.text + "\" is above " +
                                    detail::format_double(kMaxLightScale) +
                                    ", the most a relight can apply without overflowing (--exposure adds up to 64 stops)");
  }
  if (base == "off") {
    out.off = true;
    out.scale = 0.0;
    return out;
  }
  out.spectrum = parse_spectrum(base, ctx);
  if (out.scale == 0.0) out.off = true;
  return out;
}

Eigen::Matrix<double, 3, Eigen::Dynamic> relight_weights(const ColorMatching& cmf, const LightSpectrum& light,
                                                          const BinLayout& bins, LightUnits units) {
  if (light.off) return Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, bins.size());
  return relight_weights(cmf, light.spectrum, bins, units) * light.scale;
}

}  // namespace prizma::spectral
