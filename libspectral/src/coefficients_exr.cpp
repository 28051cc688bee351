// Spectral-basis coefficients in the spectral EXR (coefficients_exr.h; docs/spectral-exr.md,
// "Spectral-basis coefficients").
#include "coefficients_exr.h"

#include <ImfChannelList.h>
#include <ImfFloatVectorAttribute.h>
#include <ImfStringAttribute.h>
#include <half.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>

#include "prizma/spectral/error.h"
#include "exr/checksum.h"

namespace prizma::spectral {

bool SpectralImage::has_coefficients() const {
  return !lights.empty() &&
         std::all_of(lights.begin(), lights.end(), [](const TransportLayer& l) { return l.coefficients.k > 0; });
}

bool SpectralImage::compact() const {
  return has_coefficients() &&
         std::all_of(lights.begin(), lights.end(), [](const TransportLayer& l) { return l.data.empty(); });
}

namespace detail {
namespace {

constexpr const char* kAttrInfo = "prizma:coefficients";
constexpr const char* kAttrBasisPrefix = "prizma:basis.";
constexpr int kMaxK = 1024;  // at most one coefficient per bin
// Offset bases of the coefficients (pixel-major, k contiguous) and of the basis vectors (vector-major).

// Refuses coefficients that half cannot hold (|v| rounds past 65504).
void check_half_range(const std::vector<float>& v, std::size_t k, std::size_t width, const std::string& what,
                      const std::string& path) {
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!std::isfinite(static_cast<float>(half(v[i])))) {
      const std::size_t p = i / k;
      throw InputError(path, what + ": " + std::to_string(v[i]) + " at pixel (" + std::to_string(p % width) + ", " +
                                 std::to_string(p / width) + "), coefficient " + std::to_string(i % k) +
                                 " is beyond half's range (65504); scale it into the basis (prizma-relight compress does)");
    }
  }
}

std::string channel_name(const std::string& prefix, int j) { return prefix + "coef." + std::to_string(j); }

void check_finite(const std::vector<float>& v, const std::string& what, const std::string& path) {
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) {
      throw InputError(path, what + ": " + (std::isnan(v[i]) ? "NaN" : "infinite value") + " at value " + std::to_string(i));
    }
  }
}

}  // namespace

bool parse_coefficient_channel(const std::string& name, CoefficientChannel& out) {
  static const std::regex kPattern(R"(^(?:(.+)\.)?coef\.(0|[1-9][0-9]{0,3})$)");
  std::smatch m;
  if (!std::regex_match(name, m, kPattern)) return false;
  out.layer = m[1].matched ? m[1].str() : std::string();
  out.index = std::stoi(m[2].str());
  out.name = name;
  return true;
}

std::uint64_t add_coefficients_for_write(const SpectralImage& image, bool multi, Imf::Header& header,
                                         Imf::FrameBuffer& fb, const std::string& path,
                                         std::list<std::vector<half>>& buffers) {
  const bool any = std::any_of(image.lights.begin(), image.lights.end(),
                               [](const TransportLayer& l) { return l.coefficients.k != 0; });
  if (!any) return 0;
  const std::size_t n = static_cast<std::size_t>(image.bins.size());
  std::uint64_t sum = 0;
  nlohmann::json lights = nlohmann::json::array();
  for (const TransportLayer& light : image.lights) {
    const LayerCoefficients& c = light.coefficients;
    const std::string what = "coefficients of light \"" + light.name + "\"";
    if (c.k < 1 || c.k > static_cast<int>(std::min<std::size_t>(n, kMaxK))) {
      throw InputError(path, what + ": k = " + std::to_string(c.k) + " (every light layer needs 1.." +
                                 std::to_string(n) + " coefficients when any has them)");
    }
    const std::size_t k = static_cast<std::size_t>(c.k);
    if (c.basis.size() != k * n) {
      throw InputError(path, what + ": the basis has " + std::to_string(c.basis.size()) + " values, expected k·bins = " +
                                 std::to_string(k * n));
    }
    if (c.values.size() != k * image.pixel_count()) {
      throw InputError(path, what + ": " + std::to_string(c.values.size()) + " values, expected width·height·k = " +
                                 std::to_string(k * image.pixel_count()));
    }
    check_finite(c.basis, "basis of light \"" + light.name + "\"", path);
    check_finite(c.values, what, path);
    check_half_range(c.values, k, static_cast<std::size_t>(image.width), what, path);
    const std::string prefix = multi ? light.name + "." : std::string();
    std::vector<half>& rounded = buffers.emplace_back(c.values.begin(), c.values.end());  // nearest, ties to even
    const std::size_t x_stride = sizeof(half) * k;
    const std::size_t y_stride = x_stride * static_cast<std::size_t>(image.width);
    const char* base = reinterpret_cast<const char*>(rounded.data());
    for (std::size_t j = 0; j < k; ++j) {
      const std::string name = channel_name(prefix, static_cast<int>(j));
      header.channels().insert(name, Imf::Channel(Imf::HALF));
      fb.insert(name, Imf::Slice(Imf::HALF, const_cast<char*>(base + sizeof(half) * j), x_stride, y_stride));
    }
    header.insert(kAttrBasisPrefix + light.name, Imf::FloatVectorAttribute(Imf::FloatVector(c.basis.begin(), c.basis.end())));
    sum += exr::layer_hash(exr::LayerKind::Coefficients, rounded.data(), rounded.size());
    sum += exr::layer_hash(exr::LayerKind::Basis, c.basis.data(), c.basis.size());
    nlohmann::json errors = nlohmann::json::array();
    for (const BasisError& e : c.errors) errors.push_back({{"light", e.light}, {"percentile", e.percentile}, {"max", e.max}});
    lights.push_back({{"name", light.name}, {"k", c.k}, {"deltaE00", errors}});
  }
  nlohmann::json info = {{"version", 1}, {"compact", image.compact()}, {"lights", lights}};
  if (!image.coefficient_criterion.empty()) {
    const nlohmann::json criterion = nlohmann::json::parse(image.coefficient_criterion, nullptr, false);
    if (criterion.is_discarded() || !criterion.is_object()) {
      throw InputError(path, "the coefficients' criterion is not a JSON object");
    }
    info["criterion"] = criterion;
  }
  header.insert(kAttrInfo, Imf::StringAttribute(info.dump()));
  return sum;
}

// long on purpose: one check per coefficient attribute and channel, each naming it, in the order the file holds them.
void add_coefficients_for_read(const std::vector<CoefficientChannel>& channels, const Imf::Header& header,
                               const std::vector<std::string>& layers, int bins, SpectralImage& image,
                               Imf::FrameBuffer& fb, const Imath::Box2i& dw, const std::string& path) {
  if (channels.empty()) return;
  std::map<std::string, std::vector<const CoefficientChannel*>> by_layer;
  for (const CoefficientChannel& c : channels) by_layer[c.layer].push_back(&c);
  for (const auto& [layer, list] : by_layer) {
    if (std::find(layers.begin(), layers.end(), layer) == layers.end()) {
      throw InputError(path, "coefficient channel \"" + list.front()->name + "\" belongs to no light layer");
    }
  }
  // prizma:coefficients: k and the measured errors per light, the criterion.
  nlohmann::json info;
  if (const auto* a = header.findTypedAttribute<Imf::StringAttribute>(kAttrInfo)) {
    info = nlohmann::json::parse(a->value(), nullptr, false);
    if (info.is_discarded() || !info.is_object()) throw InputError(path, std::string(kAttrInfo) + " is not a JSON object");
  }
  if (info.contains("criterion") && info["criterion"].is_object()) image.coefficient_criterion = info["criterion"].dump();
  const std::size_t n = static_cast<std::size_t>(bins);
  for (std::size_t l = 0; l < layers.size(); ++l) {
    TransportLayer& light = image.lights[l];
    const auto it = by_layer.find(layers[l]);
    if (it == by_layer.end()) {
      throw InputError(path, "light \"" + light.name + "\" has no coefficient channels (" + channel_name(layers[l].empty() ? "" : layers[l] + ".", 0) +
                                 ", …) but other lights have: every light layer carries them or none");
    }
    std::vector<const CoefficientChannel*> list = it->second;
    std::sort(list.begin(), list.end(), [](const auto* a, const auto* b) { return a->index < b->index; });
    const int k = static_cast<int>(list.size());
    for (int j = 0; j < k; ++j) {
      if (list[static_cast<std::size_t>(j)]->index != j) {
        throw InputError(path, "coefficient channels of light \"" + light.name + "\" are not numbered 0.." +
                                   std::to_string(k - 1) + " (channel " + std::to_string(j) + " is missing)");
      }
    }
    if (k > bins) {
      throw InputError(path, "light \"" + light.name + "\" has " + std::to_string(k) + " coefficient channels for " +
                                 std::to_string(bins) + " bins (at most one per bin)");
    }
    const std::string attr = kAttrBasisPrefix + light.name;
    const auto* basis = header.findTypedAttribute<Imf::FloatVectorAttribute>(attr.c_str());
    if (basis == nullptr) {
      throw InputError(path, "light \"" + light.name + "\" has coefficient channels but no basis (float vector " + attr + ")");
    }
    if (basis->value().size() != static_cast<std::size_t>(k) * n) {
      throw InputError(path, attr + " has " + std::to_string(basis->value().size()) + " values for k = " +
                                 std::to_string(k) + " coefficients of " + std::to_string(bins) +
                                 " bins (expected k·bins = " + std::to_string(static_cast<std::size_t>(k) * n) + ")");
    }
    LayerCoefficients& c = light.coefficients;
    c.k = k;
    c.basis.assign(basis->value().begin(), basis->value().end());
    c.values.assign(image.pixel_count() * static_cast<std::size_t>(k), 0.0f);
    c.errors.clear();
    if (info.contains("lights") && info["lights"].is_array()) {
      for (const auto& entry : info["lights"]) {
        if (!entry.is_object() || entry.value("name", std::string()) != light.name) continue;
        if (entry.contains("k") && (!entry["k"].is_number_integer() || entry["k"].get<int>() != k)) {
          throw InputError(path, std::string(kAttrInfo) + " gives k = " + entry["k"].dump() + " for light \"" + light.name +
                                     "\", but the file has " + std::to_string(k) + " coefficient channels for it");
        }
        if (entry.contains("deltaE00") && entry["deltaE00"].is_array()) {
          for (const auto& e : entry["deltaE00"]) {
            if (!e.is_object()) continue;
            BasisError be;
            be.light = e.value("light", std::string());
            be.percentile = e.value("percentile", 0.0);
            be.max = e.value("max", 0.0);
            c.errors.push_back(std::move(be));
          }
        }
      }
    }
    const std::size_t x_stride = sizeof(float) * static_cast<std::size_t>(k);
    const std::size_t y_stride = x_stride * static_cast<std::size_t>(dw.max.x - dw.min.x + 1);
    for (int j = 0; j < k; ++j) {
      fb.insert(list[static_cast<std::size_t>(j)]->name,
                Imf::Slice::Make(Imf::FLOAT, c.values.data() + j, dw, x_stride, y_stride));
    }
  }
}

void check_coefficients_finite(const SpectralImage& image, const std::string& path) {
  for (const TransportLayer& light : image.lights) {
    check_finite(light.coefficients.basis, "basis of light \"" + light.name + "\"", path);
    const std::size_t k = static_cast<std::size_t>(std::max(1, light.coefficients.k));
    const std::vector<float>& v = light.coefficients.values;
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (!std::isfinite(v[i])) {
        const std::size_t p = i / k;
        std::ostringstream os;
        os << "coefficients of light \"" << light.name << "\": " << (std::isnan(v[i]) ? "NaN" : "infinite value")
           << " at pixel (" << p % static_cast<std::size_t>(image.width) << ", " << p / static_cast<std::size_t>(image.width)
           << "), coefficient " << i % k;
        throw InputError(path, os.str());
      }
    }
  }
}

std::uint64_t coefficients_checksum(const SpectralImage& image) {
  std::uint64_t sum = 0;
  for (const TransportLayer& light : image.lights) {
    if (light.coefficients.k == 0) continue;
    sum += exr::layer_hash(exr::LayerKind::Coefficients, light.coefficients.values.data(), light.coefficients.values.size());
    sum += exr::layer_hash(exr::LayerKind::Basis, light.coefficients.basis.data(), light.coefficients.basis.size());
  }
  return sum;
}

}  // namespace detail
}  // namespace prizma::spectral
