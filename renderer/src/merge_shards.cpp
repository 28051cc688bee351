// merge_shards() and the prizma:lights JSON.
#include <algorithm>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "prizma/render/render.h"
#include "prizma/spectral/error.h"

namespace prizma::render {
namespace {

using spectral::InputError;
using Range = std::pair<std::int64_t, std::int64_t>;

// "0:8" or "0:8,16:24" → ranges; throws for anything else.
std::vector<Range> parse_ranges(const std::string& text, std::int64_t samples) {
  std::vector<Range> out;
  if (text.empty()) {
    out.emplace_back(0, samples);
    return out;
  }
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t comma = std::min(text.find(',', pos), text.size());
    const std::string part = text.substr(pos, comma - pos);
    const std::size_t colon = part.find(':');
    char* end = nullptr;
    if (colon == std::string::npos) throw InputError("merge", "bad sample range \"" + text + "\"");
    const long long a = std::strtoll(part.c_str(), &end, 10);
    if (end != part.c_str() + colon) throw InputError("merge", "bad sample range \"" + text + "\"");
    const long long b = std::strtoll(part.c_str() + colon + 1, &end, 10);
    if (*end != '\0' || b <= a || a < 0) throw InputError("merge", "bad sample range \"" + text + "\"");
    out.emplace_back(a, b);
    pos = comma + 1;
  }
  return out;
}

std::string format_ranges(std::vector<Range> ranges) {
  std::sort(ranges.begin(), ranges.end());
  std::vector<Range> merged;
  for (const auto& r : ranges) {
    if (!merged.empty() && merged.back().second == r.first)
      merged.back().second = r.second;
    else
      merged.push_back(r);
  }
  std::string s;
  for (const auto& r : merged) {
    if (!s.empty()) s += ",";
    s += std::to_string(r.first) + ":" + std::to_string(r.second);
  }
  return s;
}

}  // namespace

std::string lights_to_json(const std::vector<Light>& lights) {
  nlohmann::json arr = nlohmann::json::array();
  for (const Light& l : lights) {
    arr.push_back({{"name", l.name},
                   {"direction", {l.direction.x(), l.direction.y(), l.direction.z()}},
                   {"angularSizeDeg", l.angular_size_deg},
                   {"spectrum", l.spectrum_spec}});
    if (l.emission) arr.back()["emission"] = true;  // only then: files without emission unchanged
  }
  return arr.dump();
}

std::vector<Light> lights_from_image(const spectral::SpectralImage& image) {
  std::vector<Light> out;
  nlohmann::json arr;
  try {
    if (!image.info.lights_json.empty()) arr = nlohmann::json::parse(image.info.lights_json);
  } catch (const nlohmann::json::exception&) {
    arr = nlohmann::json();
  }
  for (const auto& layer : image.lights) {
    Light l;
    l.name = layer.name;
    if (arr.is_array()) {
      for (const auto& j : arr) {
        if (!j.is_object() || j.value("name", std::string()) != layer.name) continue;
        const auto d = j.value("direction", std::vector<double>{0, 0, 0});
        if (d.size() == 3) l.direction = Eigen::Vector3d(d[0], d[1], d[2]);
        l.angular_size_deg = j.value("angularSizeDeg", 0.0);
        l.spectrum_spec = j.value("spectrum", std::string("D65"));
        l.emission = j.contains("emission") && j.at("emission").is_boolean() && j.at("emission").get<bool>();
      }
    }
    out.push_back(l);
  }
  return out;
}

spectral::SpectralImage merge_shards(const std::vector<spectral::SpectralImage>& shards) {
  if (shards.empty()) throw InputError("merge", "no shards to merge");
  const auto& first = shards.front();
  std::vector<Range> ranges;
  bool all_variance = true;
  for (std::size_t k = 0; k < shards.size(); ++k) {
    const auto& s = shards[k];
    const std::string which = "shard " + std::to_string(k + 1);
    auto refuse = [&](const std::string& what) {
      throw InputError("merge", which + ": " + what + " differs from shard 1");
    };
    if (s.width != first.width || s.height != first.height) refuse("image size");
    if (!(s.bins == first.bins)) refuse("bin layout");
    if (s.info.scene_hash != first.info.scene_hash) refuse("scene hash");
    if (s.info.seed != first.info.seed) refuse("seed");
    if (s.info.wavelength_sampling != first.info.wavelength_sampling) refuse("wavelength sampling");
    if (s.info.lights_json != first.info.lights_json || s.lights.size() != first.lights.size()) refuse("lights");
    for (std::size_t l = 0; l < s.lights.size(); ++l)
      if (s.lights[l].name != first.lights[l].name) refuse("lights");
    if (s.info.samples <= 0) throw InputError("merge", which + ": no samples");
    for (const auto& l : s.lights) all_variance = all_variance && !l.variance.empty();
    auto r = parse_ranges(s.info.sample_range, s.info.samples);
    std::int64_t n = 0;
    for (const auto& x : r) n += x.second - x.first;
    if (n != s.info.samples)
      throw InputError("merge", which + ": sample range " + s.info.sample_range + " does not hold " +
                                    std::to_string(s.info.samples) + " samples");
    ranges.insert(ranges.end(), r.begin(), r.end());
  }
  auto sorted = ranges;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t k = 1; k < sorted.size(); ++k)
    if (sorted[k].first < sorted[k - 1].second)
      throw InputError("merge", "sample ranges overlap (" + std::to_string(sorted[k - 1].first) + ":" +
                                    std::to_string(sorted[k - 1].second) + " and " +
                                    std::to_string(sorted[k].first) + ":" + std::to_string(sorted[k].second) +
                                    ")");

  // Means weighted by sample counts; variances of the mean recombined from each shard's sums.
  spectral::SpectralImage out = first;
  std::int64_t total = 0;
  for (const auto& s : shards) total += s.info.samples;
  const double n_total = static_cast<double>(total);
  for (std::size_t l = 0; l < out.lights.size(); ++l) {
    auto& layer = out.lights[l];
    const std::size_t size = layer.data.size();
    std::vector<double> sum(size, 0.0), sum_sq(all_variance ? size : 0, 0.0);
    for (const auto& s : shards) {
      const auto& src = s.lights[l];
      const double n = static_cast<double>(s.info.samples);
      for (std::size_t k = 0; k < size; ++k) {
        const double mean = src.data[k];
        sum[k] += n * mean;
        // Σx² = (n − 1)·s² + n·mean², with s² = n·(variance of the mean).
        if (all_variance) sum_sq[k] += (n - 1.0) * n * src.variance[k] + n * mean * mean;
      }
    }
    layer.variance.clear();
    if (all_variance) layer.variance.assign(size, 0.0f);
    for (std::size_t k = 0; k < size; ++k) {
      const double mean = sum[k] / n_total;
      layer.data[k] = static_cast<float>(mean);
      if (all_variance && total > 1) {
        const double var = std::max(0.0, (sum_sq[k] - n_total * mean * mean) / (n_total - 1.0));
        layer.variance[k] = static_cast<float>(var / n_total);
      }
    }
  }
  out.info.samples = total;
  out.info.sample_range = format_ranges(ranges);
  return out;
}

}  // namespace prizma::render
