// Spectral channel names: the reference layout's pattern with a layer prefix, Prizma's writing of them
// (six decimals, comma separator) and the checks a name must pass (docs/spectral-exr.md).
#include "exr/channel_names.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <regex>
#include <sstream>

#include "exr/exr_common.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/spectral_exr.h"
#include "text_util.h"

namespace prizma::spectral::exr {
namespace {

constexpr double kSpeedOfLight_m_per_s = 299792458.0;

double unit_prefix_factor(const std::string& prefix) {
  static const std::map<std::string, double> kFactors = {
      {"Y", 1e24}, {"Z", 1e21}, {"E", 1e18}, {"P", 1e15}, {"T", 1e12}, {"G", 1e9},  {"M", 1e6},  {"k", 1e3},
      {"h", 1e2},  {"da", 1e1}, {"", 1.0},   {"d", 1e-1}, {"c", 1e-2}, {"m", 1e-3}, {"u", 1e-6}, {"n", 1e-9},
      {"p", 1e-12}};
  return kFactors.at(prefix);
}

}  // namespace

// The reference reader's pattern (JCGT 2021, section 3), with an optional layer prefix in front:
//   ^((S([0-3]))|T)\.(\d*,?\d*([Ee][+-]?\d+)?)(Y|Z|E|P|T|G|M|k|h|da|d|c|m|u|n|p)?(m|Hz)$
// Returns nullopt for channels that are not spectral (R, G, B, …). Throws InputError for a spectral
// channel whose number is not a positive finite wavelength.
std::optional<ParsedChannel> parse_channel_name(const std::string& name, const std::string& path) {
  static const std::regex kPattern(
      R"(^(?:(.+)\.)?(S[0-3]|T)\.(\d*,?\d*(?:[Ee][+-]?\d+)?)(Y|Z|E|P|T|G|M|k|h|da|d|c|m|u|n|p)?(m|Hz)$)");
  std::smatch m;
  if (!std::regex_match(name, m, kPattern)) return std::nullopt;
  ParsedChannel out;
  out.layer = m[1].matched ? m[1].str() : std::string();
  out.emissive = m[2].str() != "T";
  std::string number = m[3].str();
  std::replace(number.begin(), number.end(), ',', '.');
  double value = 0.0;
  if (!detail::parse_double(number, value) || !std::isfinite(value) || value <= 0.0) {
    throw InputError(path, "channel \"" + name + "\": \"" + m[3].str() + "\" is not a positive wavelength");
  }
  value *= unit_prefix_factor(m[4].matched ? m[4].str() : std::string());
  // Metres → nm, or frequency in Hz → wavelength λ = c / f.
  out.lambda_nm = (m[5].str() == "Hz") ? kSpeedOfLight_m_per_s / value * 1e9 : value * 1e9;
  if (!std::isfinite(out.lambda_nm) || out.lambda_nm <= 0.0) {
    throw InputError(path, "channel \"" + name + "\": wavelength out of range");
  }
  return out;
}

}  // namespace prizma::spectral::exr

namespace prizma::spectral {

std::string spectral_channel_name(double lambda_nm, std::string_view layer) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, lambda_nm, std::chars_format::fixed, 6);
  std::string number(buf, res.ptr);
  std::replace(number.begin(), number.end(), '.', ',');
  return exr::layer_prefix(layer) + "T." + number + "nm";
}

void check_exr_light_name(std::string_view name, const std::string& input) {
  if (!exr::valid_light_name(name)) {
    throw InputError(input, "light name \"" + std::string(name) + "\" is not valid (letters, digits, '_' and '-' only)");
  }
  if (name == exr::kVarianceLayer) {
    throw InputError(input, "light name \"var\" is reserved for the variance layers (docs/spectral-exr.md)");
  }
}

void check_exr_bin_names(const BinLayout& bins, const std::string& input) {
  for (int i = 1; i < bins.size(); ++i) {
    const std::string a = spectral_channel_name(bins.centre_nm(i - 1));
    if (a == spectral_channel_name(bins.centre_nm(i))) {
      std::ostringstream os;
      os.precision(12);
      os << "bins " << i - 1 << " and " << i << " (centres " << bins.centre_nm(i - 1) << " and " << bins.centre_nm(i)
         << " nm) both get the channel name " << a
         << ": channel names hold the centre to 6 decimals, so bins must be wider";
      throw InputError(input, os.str());
    }
  }
}

}  // namespace prizma::spectral
