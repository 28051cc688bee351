#include "missing_channels.h"

#include "exr/exr_common.h"

#include <nlohmann/json.hpp>

#include <vector>

namespace prizma::spectral::detail {

std::string missing_channels(const SpectralImage& image, bool has_top, bool covers_top) {
  std::vector<std::string> missing;
  if (covers_top && !has_top && exr::has_named_layers(image) && !image.compact()) {
    missing.push_back("the top-level T channels (T.<λ>nm: the sum of the lights, in every file with named light layers)");
  }
  std::vector<std::string> with, without;
  for (const auto& light : image.lights) (light.variance.empty() ? without : with).push_back(light.name);
  bool rendered_with_variance = false;
  if (!image.info.render_options.empty()) {
    const nlohmann::json options = nlohmann::json::parse(image.info.render_options, nullptr, false);
    rendered_with_variance = options.is_object() && options.value("variance", false) == true;
  }
  // A denoised file whose variance was dropped (prizma:denoised "variance": "dropped") lacks them on purpose.
  if (!image.info.denoised.empty()) {
    const nlohmann::json denoised = nlohmann::json::parse(image.info.denoised, nullptr, false);
    if (denoised.is_object() && denoised.value("variance", "") == "dropped") rendered_with_variance = false;
  }
  if (!without.empty() && (!with.empty() || rendered_with_variance)) {
    std::string names;
    for (const auto& n : without) names += (names.empty() ? "" : ", ") + (n.empty() ? std::string("var") : n + ".var") + ".T.*";
    missing.push_back("the variance channels " + names +
                      (with.empty() ? " (the render wrote them: prizma:renderOptions \"variance\": true)"
                                    : " (other lights have theirs)"));
  }
  std::string out;
  for (const auto& m : missing) out += (out.empty() ? "" : " and ") + m;
  return out;
}

}  // namespace prizma::spectral::detail
