// The spectral EXR's attributes (attributes.h).
#include "exr/attributes.h"

#include <ImfDoubleAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfFloatVectorAttribute.h>
#include <ImfIntAttribute.h>
#include <ImfMatrixAttribute.h>
#include <ImfStringAttribute.h>
#include <ImfVecAttribute.h>

#include <charconv>
#include <limits>

#include "exr/exr_common.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/version.h"

namespace prizma::spectral::exr {
namespace {

std::vector<std::string> layer_names(const SpectralImage& image) {
  std::vector<std::string> names;
  for (const auto& l : image.lights) names.push_back(l.name);
  return names;
}

void put_int_or_string(Imf::Header& header, const char* name, std::int64_t v) {
  if (v >= std::numeric_limits<int>::min() && v <= std::numeric_limits<int>::max()) {
    header.insert(name, Imf::IntAttribute(static_cast<int>(v)));
  } else {
    header.insert(name, Imf::StringAttribute(std::to_string(v)));
  }
}

// prizma:seed: an int when it fits (every file before 0.3 too), else its unsigned decimal string.
// (Files before 0.3 stored seeds ≥ 2^63 as negative numbers, the seed minus 2^64: read_seed.)
void put_seed(Imf::Header& header, const char* name, std::uint64_t seed) {
  if (seed <= static_cast<std::uint64_t>(std::numeric_limits<int>::max())) {
    header.insert(name, Imf::IntAttribute(static_cast<int>(seed)));
  } else {
    header.insert(name, Imf::StringAttribute(std::to_string(seed)));
  }
}

std::int64_t int_attr(const Imf::Header& h, const char* name, const std::string& path) {
  if (const auto* a = h.findTypedAttribute<Imf::IntAttribute>(name)) return a->value();
  if (const auto* s = find_string_attr(h, name)) {
    std::int64_t v = 0;
    const auto res = std::from_chars(s->data(), s->data() + s->size(), v);
    if (res.ec != std::errc() || res.ptr != s->data() + s->size()) {
      throw InputError(path, std::string(name) + ": \"" + *s + "\" is not an integer");
    }
    return v;
  }
  return 0;
}

// prizma:seed as put_seed writes it. A negative value (an int or a string) is a file written before
// 0.3, which stored the 64-bit seed as a signed number: seed − 2^64 for seeds from 2^63 on.
std::uint64_t read_seed(const Imf::Header& h, const char* name, const std::string& path) {
  if (const auto* a = h.findTypedAttribute<Imf::IntAttribute>(name)) {
    return static_cast<std::uint64_t>(static_cast<std::int64_t>(a->value()));
  }
  const auto* s = find_string_attr(h, name);
  if (s == nullptr) return 0;
  const char* begin = s->data();
  const char* end = s->data() + s->size();
  if (!s->empty() && s->front() == '-') {
    std::int64_t v = 0;
    const auto res = std::from_chars(begin, end, v);
    if (res.ec == std::errc() && res.ptr == end) return static_cast<std::uint64_t>(v);
  } else {
    std::uint64_t v = 0;
    const auto res = std::from_chars(begin, end, v);
    if (res.ec == std::errc() && res.ptr == end) return v;
  }
  throw InputError(path, std::string(name) + ": \"" + *s + "\" is not a 64-bit seed");
}

// prizma:misLaneGroups: 0 (not recorded) or a lane group count no render exceeds (one per bin).
void check_mis_lane_groups(std::int64_t groups, const std::string& path) {
  if (groups < 0 || groups > BinLayout::kMaxBins)
    throw InputError(path, std::string(kAttrMisLaneGroups) + ": " + std::to_string(groups) +
                               " is not a lane group count (1 to " + std::to_string(BinLayout::kMaxBins) + ")");
}

}  // namespace

void put_attributes(Imf::Header& header, const SpectralImage& image, const std::string& path) {
  const std::string& p = path;
  header.insert("spectralLayoutVersion", Imf::StringAttribute(kLayoutVersion));
  {
    Imf::FloatVector edges;
    std::string exact;
    for (double e : image.bins.edges_nm()) {
      edges.push_back(static_cast<float>(e));
      char buf[64];
      const auto res = std::to_chars(buf, buf + sizeof buf, e, std::chars_format::general, 17);
      if (!exact.empty()) exact += ' ';
      exact.append(buf, res.ptr);
    }
    header.insert(kAttrEdges, Imf::FloatVectorAttribute(edges));
    header.insert(kAttrEdgesExact, Imf::StringAttribute(exact));
  }
  const SpectralExrInfo& info = image.info;
  check_light_records(info.light_records, layer_names(image), p);
  check_mis_lane_groups(info.mis_lane_groups, p);
  header.insert(kAttrLights, Imf::StringAttribute(light_records_json(
                                 info.light_records.empty() ? light_records_for(layer_names(image)) : info.light_records)));
  put_int_or_string(header, kAttrSamples, info.samples);
  put_seed(header, kAttrSeed, info.seed);
  if (!info.sample_range.empty()) header.insert(kAttrSampleRange, Imf::StringAttribute(info.sample_range));
  if (!info.scene_hash.empty()) header.insert(kAttrSceneHash, Imf::StringAttribute(info.scene_hash));
  header.insert(kAttrVersion, Imf::StringAttribute(info.version.empty() ? prizma_version() : info.version));
  if (!info.wavelength_sampling.empty()) {
    header.insert(kAttrWavelengthSampling, Imf::StringAttribute(info.wavelength_sampling));
  }
  if (info.mis_lane_groups > 0) header.insert(kAttrMisLaneGroups, Imf::IntAttribute(info.mis_lane_groups));
  if (!info.scene_path.empty()) header.insert(kAttrScenePath, Imf::StringAttribute(info.scene_path));
  if (!info.render_options.empty()) header.insert(kAttrRenderOptions, Imf::StringAttribute(info.render_options));
  if (!info.denoised.empty()) header.insert(kAttrDenoised, Imf::StringAttribute(info.denoised));
}

SpectralExrInfo read_attributes(const Imf::Header& header, const std::string& path) {
  const std::string& p = path;
  SpectralExrInfo info;
  for (auto it = header.begin(); it != header.end(); ++it) {
    if (std::string_view(it.name()).rfind("prizma:", 0) == 0) info.is_prizma = true;
  }
  if (const auto* s = find_string_attr(header, kAttrLights)) info.light_records = parse_light_records(*s, p + ": " + kAttrLights);
  if (const auto* s = find_string_attr(header, kAttrSampleRange)) info.sample_range = *s;
  if (const auto* s = find_string_attr(header, kAttrSceneHash)) info.scene_hash = *s;
  if (const auto* s = find_string_attr(header, kAttrVersion)) info.version = *s;
  if (const auto* s = find_string_attr(header, kAttrWavelengthSampling)) info.wavelength_sampling = *s;
  if (const auto* s = find_string_attr(header, kAttrScenePath)) info.scene_path = *s;
  if (const auto* s = find_string_attr(header, kAttrRenderOptions)) info.render_options = *s;
  if (const auto* s = find_string_attr(header, kAttrDenoised)) info.denoised = *s;
  info.samples = int_attr(header, kAttrSamples, p);
  info.seed = read_seed(header, kAttrSeed, p);
  const std::int64_t groups = int_attr(header, kAttrMisLaneGroups, p);
  check_mis_lane_groups(groups, p);
  info.mis_lane_groups = static_cast<int>(groups);
  return info;
}

const std::string* find_string_attr(const Imf::Header& h, const char* name) {
  const auto* a = h.findTypedAttribute<Imf::StringAttribute>(name);
  return a ? &a->value() : nullptr;
}

// prizma:binEdgesNm in any numeric form OpenEXR holds: Prizma writes a float vector, but
// OpenImageIO (oiiotool) rewrites a float array of 2, 3, 9 or 16 values as v2f, v3f, m33f or
// m44f, and other tools may write doubles. Empty when absent; InputError for any other type.
std::optional<std::vector<double>> edges_attribute(const Imf::Header& h, const char* name, const std::string& p) {
  const auto it = h.find(name);
  if (it == h.end()) return std::nullopt;
  const Imf::Attribute* attr = &it.attribute();
  std::vector<double> v;
  auto take = [&](const auto* values, std::size_t n) { v.assign(values, values + n); };
  if (const auto* a = dynamic_cast<const Imf::FloatVectorAttribute*>(attr)) take(a->value().data(), a->value().size());
  else if (const auto* a2f = dynamic_cast<const Imf::V2fAttribute*>(attr)) take(&a2f->value()[0], 2);
  else if (const auto* a3f = dynamic_cast<const Imf::V3fAttribute*>(attr)) take(&a3f->value()[0], 3);
  else if (const auto* m3f = dynamic_cast<const Imf::M33fAttribute*>(attr)) take(&m3f->value()[0][0], 9);
  else if (const auto* m4f = dynamic_cast<const Imf::M44fAttribute*>(attr)) take(&m4f->value()[0][0], 16);
  else if (const auto* a2d = dynamic_cast<const Imf::V2dAttribute*>(attr)) take(&a2d->value()[0], 2);
  else if (const auto* a3d = dynamic_cast<const Imf::V3dAttribute*>(attr)) take(&a3d->value()[0], 3);
  else if (const auto* m3d = dynamic_cast<const Imf::M33dAttribute*>(attr)) take(&m3d->value()[0][0], 9);
  else if (const auto* m4d = dynamic_cast<const Imf::M44dAttribute*>(attr)) take(&m4d->value()[0][0], 16);
  else if (const auto* f = dynamic_cast<const Imf::FloatAttribute*>(attr)) v = {f->value()};
  else if (const auto* d = dynamic_cast<const Imf::DoubleAttribute*>(attr)) v = {d->value()};
  else {
    throw InputError(p, std::string(name) + " has type " + attr->typeName() +
                            "; expected the bin edges as floats (floatvector, v2f, v3f, m33f, m44f or doubles)");
  }
  return v;
}

}  // namespace prizma::spectral::exr
