#pragma once
// Spectral channel names (docs/spectral-exr.md; the reference reader's pattern, JCGT 2021 §3) with
// Prizma's optional layer prefix: parsing them into a layer and a wavelength (internal).
#include <optional>
#include <string>

namespace prizma::spectral::exr {

struct ParsedChannel {
  std::string layer;  // text before the spectral part ("" for top level, "key", "key.var", "var")
  bool emissive = false;
  double lambda_nm = 0.0;
};

// nullopt for channels that are not spectral (R, G, B, …). Throws InputError(path, …) for a spectral
// channel whose number is not a positive finite wavelength.
std::optional<ParsedChannel> parse_channel_name(const std::string& name, const std::string& path);

}  // namespace prizma::spectral::exr
