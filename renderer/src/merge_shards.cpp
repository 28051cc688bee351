// merge_shards() and the scene's lights as prizma:lights records.
#include <algorithm>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "prizma/render/render.h"
#include "prizma/render/sample_range.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/guide_names.h"

namespace prizma::render {
namespace {

using spectral::InputError;

// prizma:renderOptions of the merge: the shards' common options with the union as the target range
// (so that a merged file can be extended with --resume), or none when the shards differ in more.
std::string merged_options(const std::vector<spectral::SpectralImage>& shards,
                           const std::vector<SampleRange>& joined) {
  nlohmann::json common;
  for (const auto& s : shards) {
    nlohmann::json j = nlohmann::json::parse(s.info.render_options, nullptr, /*allow_exceptions=*/false);
    if (!j.is_object()) return {};
    j.erase("samples");
    if (common.is_null())
      common = j;
    else if (j != common)
      return {};
  }
  if (joined.size() == 1) common["samples"] = joined.front().to_string();
  return common.dump();
}

}  // namespace

std::vector<spectral::LightRecord> light_records(const std::vector<Light>& lights) {
  const auto array3 = [](const Eigen::Vector3d& v) { return std::array<double, 3>{v.x(), v.y(), v.z()}; };
  std::vector<spectral::LightRecord> out;
  for (const Light& l : lights) {
    spectral::LightRecord& r = out.emplace_back();
    r.name = l.name;
    r.spectrum = l.spectrum_spec;
    r.direction = array3(l.direction);
    r.angular_size_deg = l.angular_size_deg;
    r.emission = l.emission;
    if (l.is_point) {  // point, sphere and spot lights
      r.position = array3(l.position);
      r.radius = l.radius;
      if (l.spot_direction.squaredNorm() > 0.0)
        r.spot = spectral::SpotRecord{array3(l.spot_direction), l.spot_cone_deg, l.spot_falloff_deg};
    }
    if (l.environment_map) {
      r.environment = l.environment_file;
      r.rotation_deg = l.rotation_deg;
    }
  }
  return out;
}

std::vector<Light> lights_from_image(const spectral::SpectralImage& image) {
  std::vector<Light> out;
  for (const auto& layer : image.lights) {
    Light& l = out.emplace_back();
    l.name = layer.name;
    for (const spectral::LightRecord& r : image.info.light_records) {
      if (r.name != layer.name) continue;
      if (r.direction) l.direction = Eigen::Vector3d((*r.direction)[0], (*r.direction)[1], (*r.direction)[2]);
      l.angular_size_deg = r.angular_size_deg.value_or(0.0);
      l.emission = r.emission;
    }
    l.spectrum_spec = spectral::default_spectrum(image.info.light_records, layer.name, image.lights.size());
  }
  return out;
}

// One per-pixel plane of the shards merged into `mean` (and `variance`, when with_variance): means
// weighted by sample counts; variances of the mean recombined as in Chan et al.'s parallel algorithm,
// M2 = Σ M2_i + Σ n_i·(mean_i − mean)², with M2_i = (n_i − 1)·s_i² and s_i² = n_i·(variance of the
// mean); unlike Σx² − n·mean² this does not cancel when the variance is small next to mean².
// plane(s) gives shard s's (values, variances).
template <class Plane>
void merge_plane(const std::vector<spectral::SpectralImage>& shards, std::int64_t total, bool with_variance,
                 const Plane& plane, std::vector<float>& mean, std::vector<float>& variance) {
  const double n_total = static_cast<double>(total);
  const std::size_t size = mean.size();
  std::vector<double> sum(size, 0.0);
  for (const auto& s : shards) {
    const std::vector<float>& src = *plane(s).first;
    const double n = static_cast<double>(s.info.samples);
    for (std::size_t k = 0; k < size; ++k) sum[k] += n * static_cast<double>(src[k]);
  }
  for (std::size_t k = 0; k < size; ++k) sum[k] /= n_total;  // now the mean
  variance.clear();
  if (with_variance && total > 1) {
    std::vector<double> m2(size, 0.0);
    for (const auto& s : shards) {
      const auto [src, src_var] = plane(s);
      const double n = static_cast<double>(s.info.samples);
      for (std::size_t k = 0; k < size; ++k) {
        const double d = static_cast<double>((*src)[k]) - sum[k];
        m2[k] += (n - 1.0) * n * static_cast<double>((*src_var)[k]) + n * d * d;
      }
    }
    variance.resize(size);
    for (std::size_t k = 0; k < size; ++k) variance[k] = static_cast<float>(std::max(0.0, m2[k] / (n_total - 1.0)) / n_total);
  } else if (with_variance) {
    variance.assign(size, 0.0f);
  }
  for (std::size_t k = 0; k < size; ++k) mean[k] = static_cast<float>(sum[k]);
}

void require_raw_samples(const spectral::SpectralImage& image, const std::string& name) {
  if (!image.info.denoised.empty())
    throw InputError(name, "is " + spectral::denoised_summary(image.info) +
                               ": samples cannot be added to filtered values (merge or --resume the raw renders, then denoise)");
}

// long on purpose: the shard checks and the weighted merge of every layer kind share one plan of sample counts.
spectral::SpectralImage merge_shards(const std::vector<spectral::SpectralImage>& shards,
                                     const std::vector<std::string>& names) {
  if (shards.empty()) throw InputError("merge", "no shards to merge");
  auto name = [&](std::size_t k) { return k < names.size() ? names[k] : "shard " + std::to_string(k + 1); };
  const auto& first = shards.front();
  struct Held {
    SampleRange range;
    std::size_t shard;
  };
  std::vector<Held> held;
  bool all_variance = true;
  for (std::size_t k = 0; k < shards.size(); ++k) {
    const auto& s = shards[k];
    auto refuse = [&](const std::string& what) {
      throw InputError(name(k), what + " differs from " + name(0));
    };
    if (s.width != first.width || s.height != first.height) refuse("image size");
    if (!(s.bins == first.bins)) refuse("bin layout");
    if (s.info.scene_hash != first.info.scene_hash) refuse("scene hash");
    if (s.info.seed != first.info.seed) refuse("seed");
    if (s.info.wavelength_sampling != first.info.wavelength_sampling) refuse("wavelength sampling");
    if (recorded_mis_lane_groups(s.info) != recorded_mis_lane_groups(first.info)) refuse("spectral MIS's lane groups (prizma:misLaneGroups)");
    if (s.info.light_records != first.info.light_records || s.lights.size() != first.lights.size()) refuse("lights");
    for (std::size_t l = 0; l < s.lights.size(); ++l)
      if (s.lights[l].name != first.lights[l].name) refuse("lights");
    if (s.info.samples <= 0) throw InputError(name(k), "holds no samples");
    require_raw_samples(s, name(k));
    if (!(s.reradiation == first.reradiation)) refuse("bispectral channels");
    for (const auto& l : s.lights) all_variance = all_variance && !l.variance.empty();
    const auto r = s.info.sample_range.empty()
                       ? std::vector<SampleRange>{{0, s.info.samples}}
                       : parse_sample_ranges(s.info.sample_range, name(k) + ": prizma:sampleRange");
    std::int64_t n = 0;
    for (const auto& x : r) n += x.size();
    if (n != s.info.samples)
      throw InputError(name(k), "prizma:sampleRange " + s.info.sample_range + " does not hold " +
                                    std::to_string(s.info.samples) + " samples (prizma:samples)");
    for (const auto& x : r) held.push_back({x, k});
  }
  std::sort(held.begin(), held.end(), [](const Held& a, const Held& b) {
    return a.range != b.range ? a.range < b.range : a.shard < b.shard;
  });
  for (std::size_t k = 1; k < held.size(); ++k) {
    const Held& a = held[k - 1];
    const Held& b = held[k];
    if (b.range.begin < a.range.end)
      throw InputError(name(b.shard), "samples " + b.range.to_string() + " overlap samples " +
                                          a.range.to_string() + " of " +
                                          (a.shard == b.shard ? std::string("the same file") : name(a.shard)) +
                                          " (sample ranges overlap)");
  }
  std::vector<SampleRange> ranges;
  for (const auto& h : held) ranges.push_back(h.range);

  // Means weighted by sample counts, variances of the mean recombined (merge_plane).
  spectral::SpectralImage out = first;
  std::int64_t total = 0;
  for (const auto& s : shards) total += s.info.samples;
  const double n_total = static_cast<double>(total);
  for (std::size_t l = 0; l < out.lights.size(); ++l) {
    auto& layer = out.lights[l];
    merge_plane(shards, total, all_variance, [l](const spectral::SpectralImage& s) {
      return std::pair(&s.lights[l].data, &s.lights[l].variance);
    }, layer.data, layer.variance);
    if (!out.reradiation.empty()) {  // bispectral terms: the same weighted mean
      std::vector<double> rs(layer.reradiation.size(), 0.0);
      for (const auto& s : shards)
        for (std::size_t k = 0; k < rs.size(); ++k)
          rs[k] += static_cast<double>(s.info.samples) * static_cast<double>(s.lights[l].reradiation[k]);
      for (std::size_t k = 0; k < rs.size(); ++k) layer.reradiation[k] = static_cast<float>(rs[k] / n_total);
    }
  }
  // Guide layers (--features): merged alike when every shard has the same ones (by name: a file read
  // back lists them in its channels' order, a render in its own), else dropped.
  auto find_guide = [](const spectral::SpectralImage& s, const std::string& guide_name) -> const spectral::GuideLayer* {
    for (const spectral::GuideLayer& g : s.guides)
      if (g.name == guide_name) return &g;
    return nullptr;
  };
  bool same_guides = true;
  for (const auto& s : shards) {
    same_guides = same_guides && s.guides.size() == first.guides.size();
    for (std::size_t g = 0; same_guides && g < first.guides.size(); ++g) {
      const spectral::GuideLayer* mine = find_guide(s, first.guides[g].name);
      same_guides = mine && !mine->variance.empty();
    }
  }
  if (!same_guides) out.guides.clear();
  for (std::size_t g = 0; g < out.guides.size(); ++g) {
    // The first-hit guides are the same in every shard (hit_guides.h): kept as they are.
    if (spectral::exact_guide(out.guides[g].name)) continue;
    const std::string guide_name = out.guides[g].name;
    merge_plane(shards, total, true, [&find_guide, guide_name](const spectral::SpectralImage& s) {
      const spectral::GuideLayer* mine = find_guide(s, guide_name);
      return std::pair(&mine->value, &mine->variance);
    }, out.guides[g].value, out.guides[g].variance);
  }
  out.info.samples = total;
  out.info.sample_range = format_sample_ranges(ranges);
  out.info.render_options = merged_options(shards, join_sample_ranges(ranges));
  return out;
}

}  // namespace prizma::render
