// Guide layers in the spectral EXR (guides_exr.h).
#include "guides_exr.h"

#include <ImfChannelList.h>

#include <cmath>
#include <map>
#include <set>

#include "exr/checksum.h"
#include "exr/exr_common.h"
#include "prizma/spectral/error.h"

namespace prizma::spectral::detail {
namespace {

constexpr std::string_view kPrefix = "guide.";
constexpr std::string_view kVarianceSuffix = ".var";

bool valid_guide_name(const std::string& name) {
  if (name.empty()) return false;
  for (const char c : name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  return true;
}

void add_slice(Imf::FrameBuffer& fb, const std::string& channel, float* base, const Imath::Box2i& dw, int width) {
  fb.insert(channel, Imf::Slice::Make(Imf::FLOAT, base, dw, sizeof(float), sizeof(float) * static_cast<std::size_t>(width)));
}

void check_values(const std::vector<float>& v, bool variance, const std::string& what, const std::string& p) {
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!std::isfinite(v[i]) || (variance && v[i] < 0.0f))
      throw InputError(p, what + ": value " + std::to_string(v[i]) + " at pixel " + std::to_string(i));
}

}  // namespace

bool parse_guide_channel(const std::string& channel, std::string& name, bool& variance) {
  if (channel.rfind(kPrefix, 0) != 0) return false;
  name = channel.substr(kPrefix.size());
  variance = name.size() > kVarianceSuffix.size() &&
             name.compare(name.size() - kVarianceSuffix.size(), kVarianceSuffix.size(), kVarianceSuffix) == 0;
  if (variance) name.resize(name.size() - kVarianceSuffix.size());
  return valid_guide_name(name);
}

std::uint64_t add_guides_for_write(const SpectralImage& image, Imf::Header& header, Imf::FrameBuffer& fb,
                                   const std::string& p) {
  std::set<std::string> names;
  const Imath::Box2i dw(Imath::V2i(0, 0), Imath::V2i(image.width - 1, image.height - 1));
  for (const GuideLayer& g : image.guides) {
    const std::string what = "guide \"" + g.name + "\"";
    if (!valid_guide_name(g.name)) throw InputError(p, what + ": a guide's name is letters, digits and '_'");
    if (!names.insert(g.name).second) throw InputError(p, "two guides are named \"" + g.name + "\"");
    if (g.value.size() != image.pixel_count() || (!g.variance.empty() && g.variance.size() != image.pixel_count()))
      throw InputError(p, what + ": " + std::to_string(g.value.size()) + " values and " +
                              std::to_string(g.variance.size()) + " variances for " +
                              std::to_string(image.pixel_count()) + " pixels");
    check_values(g.value, false, what, p);
    check_values(g.variance, true, what + " variance", p);
    const std::string channel = std::string(kPrefix) + g.name;
    header.channels().insert(channel, Imf::Channel(Imf::FLOAT));
    add_slice(fb, channel, const_cast<float*>(g.value.data()), dw, image.width);
    if (!g.variance.empty()) {
      header.channels().insert(channel + std::string(kVarianceSuffix), Imf::Channel(Imf::FLOAT));
      add_slice(fb, channel + std::string(kVarianceSuffix), const_cast<float*>(g.variance.data()), dw, image.width);
    }
  }
  return guides_checksum(image);
}

void add_guides_for_read(const Imf::Header& header, SpectralImage& image, Imf::FrameBuffer& fb, const Imath::Box2i& dw,
                         const std::string& p) {
  std::map<std::string, std::pair<std::string, std::string>> found;  // name → (value channel, variance channel)
  for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
    std::string name;
    bool variance = false;
    if (!parse_guide_channel(it.name(), name, variance)) continue;
    (variance ? found[name].second : found[name].first) = it.name();
  }
  image.guides.clear();
  image.guides.reserve(found.size());  // the slices point into the planes: no reallocation after this
  for (const auto& [name, channels] : found) {
    if (channels.first.empty()) throw InputError(p, "channel \"" + channels.second + "\" has no guide channel guide." + name);
    GuideLayer& g = image.guides.emplace_back();
    g.name = name;
    g.value.assign(image.pixel_count(), 0.0f);
    add_slice(fb, channels.first, g.value.data(), dw, image.width);
    if (!channels.second.empty()) {
      g.variance.assign(image.pixel_count(), 0.0f);
      add_slice(fb, channels.second, g.variance.data(), dw, image.width);
    }
  }
}

void check_guides_finite(const SpectralImage& image, const std::string& p) {
  for (const GuideLayer& g : image.guides) {
    check_values(g.value, false, "guide." + g.name, p);
    check_values(g.variance, true, "guide." + g.name + ".var", p);
  }
}

std::uint64_t guides_checksum(const SpectralImage& image) {
  std::uint64_t sum = 0;
  for (const GuideLayer& g : image.guides) {
    sum += exr::layer_hash(exr::LayerKind::Guide, g.value.data(), g.value.size());
    if (!g.variance.empty()) sum += exr::layer_hash(exr::LayerKind::GuideVariance, g.variance.data(), g.variance.size());
  }
  return sum;
}

}  // namespace prizma::spectral::detail
