// denoised_summary (spectral_exr.h): prizma:denoised in words, for every reader that shows a file.
#include <nlohmann/json.hpp>

#include <string>

#include "prizma/spectral/spectral_exr.h"

namespace prizma::spectral {

std::string denoised_summary(const SpectralExrInfo& info) {
  if (info.denoised.empty()) return "";
  const nlohmann::json r = nlohmann::json::parse(info.denoised, nullptr, false);
  if (!r.is_object()) return "denoised (prizma:denoised unreadable)";
  auto text = [&](const char* key) {
    const auto it = r.find(key);
    return it != r.end() && it->is_string() ? it->get<std::string>() : std::string();
  };
  std::string guides;
  if (const auto it = r.find("guides"); it != r.end() && it->is_array())
    for (const auto& g : *it)
      if (g.is_string()) guides += (guides.empty() ? "" : ", ") + g.get<std::string>();
  const std::string version = text("version"), method = text("method"), variance = text("variance");
  std::string out = "denoised";
  if (!version.empty()) out += " by prizma " + version;
  if (!method.empty()) out += ": " + method;
  if (!guides.empty()) out += " on " + guides;
  if (!variance.empty()) out += "; variance " + variance;
  return out;
}

}  // namespace prizma::spectral
