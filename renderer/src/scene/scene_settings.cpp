// The scene's bins and sampling (docs/scene-format.md, "Rendering"): the bin layout, samples, seed,
// bounces, the wavelength sampling, the sampler, the event probabilities, spectral MIS's lane groups
// and the error target.
#include "prizma/spectral/spectral_exr.h"
#include "scene_reader.h"

namespace prizma::render::scene_file {

std::uint64_t read_seed(const Reader& rd, const json& j, const std::string& path) {
  if (!j.is_number_integer() || (!j.is_number_unsigned() && j.get<std::int64_t>() < 0)) {
    rd.fail(path, "must be an integer ≥ 0 (got " + Reader::describe(j) + ")");
  }
  return j.get<std::uint64_t>();
}

void read_settings(const Reader& rd, const json& root, RenderSettings& s) {
  if (root.contains("bins")) {
    s.bins = spectral::BinLayout::parse(rd.string(root.at("bins"), "bins"), rd.input("bins"));
    spectral::check_exr_bin_names(s.bins, rd.input("bins"));
  }
  if (root.contains("samples")) s.sample_end = rd.integer(root.at("samples"), "samples", 1, kMaxSamples);
  if (root.contains("seed")) s.seed = read_seed(rd, root.at("seed"), "seed");
  if (root.contains("max_bounces")) s.max_bounces = static_cast<int>(rd.integer(root.at("max_bounces"), "max_bounces", -1, kMaxBounces));
  if (root.contains("wavelength_sampling")) {
    const std::string w = rd.string(root.at("wavelength_sampling"), "wavelength_sampling");
    if (w == "auto") s.wavelength_sampling = WavelengthSampling::Auto;
    else if (w == "spectral-tracking") s.wavelength_sampling = WavelengthSampling::SpectralTracking;
    else if (w == "spectral-mis") s.wavelength_sampling = WavelengthSampling::SpectralMis;
    else if (w == "single") s.wavelength_sampling = WavelengthSampling::Single;
    else rd.fail("wavelength_sampling", "must be \"auto\", \"spectral-tracking\", \"spectral-mis\" or \"single\" (got \"" + w + "\")");
  }
  if (root.contains("sampler"))
    s.sampler = parse_sampler(rd.string(root.at("sampler"), "sampler"), rd.input("sampler"));
  if (root.contains("event_probabilities"))
    s.event_probabilities = parse_event_probabilities(rd.string(root.at("event_probabilities"), "event_probabilities"),
                                                      rd.input("event_probabilities"));
  if (root.contains("mis_lane_groups")) {
    const json& g = root.at("mis_lane_groups");
    if (g.is_string()) {
      if (g.get<std::string>() != "auto")
        rd.fail("mis_lane_groups", "must be \"auto\" or an integer ≥ 1 (got " + Reader::describe(g) + ")");
      s.mis_lane_groups = 0;
    } else {
      s.mis_lane_groups = static_cast<int>(rd.integer(g, "mis_lane_groups", 1, spectral::BinLayout::kMaxBins));
    }
  }
  if (root.contains("target_error")) {
    s.target_error = rd.number(root.at("target_error"), "target_error");
    if (s.target_error < 0.0) rd.fail("target_error", "must be ≥ 0 (got " + num(s.target_error) + ")");
  }
}

std::pair<std::int64_t, std::int64_t> integer_field_range(const std::string& field) {
  if (field == "camera.width" || field == "camera.height") return {1, kMaxImageSide};
  if (field == "samples") return {1, kMaxSamples};
  if (field == "max_bounces") return {-1, kMaxBounces};
  throw std::logic_error("integer_field_range: unknown field " + field);
}

}  // namespace prizma::render::scene_file
