// prizma:checksum (checksum.h).
#include "exr/checksum.h"

#include <ImfChannelList.h>
#include <ImfStringAttribute.h>

#include <cstdio>
#include <map>

#include "bispectral_exr.h"
#include "coefficients_exr.h"
#include "guides_exr.h"
#include "missing_channels.h"
#include "prizma/spectral/error.h"
#include "text_util.h"

namespace prizma::spectral::exr {
namespace {

// v1: the light and variance layers, summed over layers modulo 2⁶⁴.
std::uint64_t light_layers_hash(const SpectralImage& image) {
  std::uint64_t sum = 0;
  for (const auto& light : image.lights) {
    if (light.data.empty()) continue;  // a compact file: coefficients only
    sum += layer_hash(LayerKind::Transport, light.data.data(), light.data.size());
    if (!light.variance.empty()) sum += layer_hash(LayerKind::Variance, light.variance.data(), light.variance.size());
  }
  return sum;
}

// What the header says about a file whose pixels do not match prizma:checksum: the signs that
// another tool re-encoded it (such tools copy prizma: attributes but not the exact values), or "".
std::string reencoding_signs(const Imf::Header& h) {
  std::vector<std::string> signs;
  const Imf::Compression c = h.compression();
  // Prizma writes small images uncompressed and larger ones with PIZ (earlier versions: PIZ at every
  // size, so PIZ is no sign).
  const bool small = prizma_compression(h) == Imf::NO_COMPRESSION;
  if (c != Imf::PIZ_COMPRESSION && (c != Imf::NO_COMPRESSION || !small)) {
    static const std::map<Imf::Compression, std::pair<const char*, bool>> kNames = {
        {Imf::NO_COMPRESSION, {"none", false}},  {Imf::RLE_COMPRESSION, {"RLE", false}},
        {Imf::ZIPS_COMPRESSION, {"ZIPS", false}}, {Imf::ZIP_COMPRESSION, {"ZIP", false}},
        {Imf::PXR24_COMPRESSION, {"PXR24", true}}, {Imf::B44_COMPRESSION, {"B44", true}},
        {Imf::B44A_COMPRESSION, {"B44A", true}},  {Imf::DWAA_COMPRESSION, {"DWAA", true}},
        {Imf::DWAB_COMPRESSION, {"DWAB", true}}};
    const auto it = kNames.find(c);
    const std::string name = it == kNames.end() ? "unknown" : it->second.first;
    const bool lossy = it != kNames.end() && it->second.second;
    signs.push_back(std::string("its compression is ") + (lossy ? "the lossy " : "") + name +
                    (small ? ", Prizma writes an image this small uncompressed" : ", Prizma writes PIZ"));
  }
  bool any_half = false, any_float = false;
  for (auto it = h.channels().begin(); it != h.channels().end(); ++it) {
    // Coefficient channels are half in every Prizma file (float in files of 2026-12-01), whatever the bins'.
    if (detail::CoefficientChannel cc; detail::parse_coefficient_channel(it.name(), cc)) continue;
    (it.channel().type == Imf::HALF ? any_half : any_float) = true;
  }
  if (any_half && any_float) signs.push_back("it mixes half and float channels");
  if (const auto* sw = h.findTypedAttribute<Imf::StringAttribute>("Software")) {
    const std::string who = sw->value().substr(0, sw->value().find(" : "));
    signs.push_back("it was written by " + detail::printable(who.substr(0, 80)));
  }
  std::string out;
  for (const auto& s : signs) out += (out.empty() ? "" : "; ") + s;
  return out;
}

}  // namespace

std::string checksum_string(std::uint64_t sum, const char* scheme) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(sum));
  return std::string(scheme) + buf;
}

std::vector<float> sum_of_lights(const SpectralImage& image) {
  const std::size_t n = image.lights.empty() ? 0 : image.lights.front().data.size();
  std::vector<float> sum(n, 0.0f);
  for (std::size_t k = 0; k < n; ++k) {
    double s = 0.0;
    for (const auto& light : image.lights) s += light.data[k];
    sum[k] = static_cast<float>(s);
  }
  return sum;
}

void verify_checksum(const std::string& p, const Imf::Header& header, const std::string& stored,
                     const SpectralImage& image, const std::vector<float>* top, const std::string& unverified_read) {
  std::string expected;
  if (stored.rfind(kChecksumScheme, 0) == 0) {
    std::uint64_t sum = light_layers_hash(image);
    if (top != nullptr) sum += layer_hash(LayerKind::Sum, top->data(), top->size());
    sum += detail::reradiation_checksum(image);  // 0 without bispectral terms
    sum += detail::coefficients_checksum(image);  // 0 without spectral-basis coefficients
    sum += detail::guides_checksum(image);        // 0 without guide layers
    expected = checksum_string(sum);
  } else if (stored.rfind(kChecksumSchemeV1, 0) == 0) {
    expected = checksum_string(light_layers_hash(image), kChecksumSchemeV1);
  } else {
    throw InputError(p, std::string(kAttrChecksum) + " \"" + stored + "\" is not of a known kind (expected " +
                            kChecksumScheme + "<16 hex digits>, or " + kChecksumSchemeV1 + "<16 hex digits> in older files)");
  }
  if (stored == expected) return;
  // Channels another tool left out (oiiotool --ch) are named, not taken for a re-encoding.
  if (const std::string missing = detail::missing_channels(image, top != nullptr, stored.rfind(kChecksumScheme, 0) == 0);
      !missing.empty()) {
    throw InputError(p, "pixel data do not match " + std::string(kAttrChecksum) + ": the file lacks " + missing +
                            ", which the checksum covers: another tool left them out (oiiotool --ch, say); " +
                            unverified_read + " reads what is there");
  }
  const std::string signs = reencoding_signs(header);
  if (signs.empty()) {
    throw InputError(p, "pixel data do not match " + std::string(kAttrChecksum) + " (the file is damaged; " +
                            unverified_read + " reads it anyway)");
  }
  throw InputError(p, "pixel data do not match " + std::string(kAttrChecksum) +
                          ": the file was probably re-encoded by another tool (" + signs +
                          "), which kept the attribute but not the exact values; " + unverified_read + " reads it");
}

}  // namespace prizma::spectral::exr

namespace prizma::spectral {

std::string spectral_pixel_checksum(const SpectralImage& image) {
  std::uint64_t sum = exr::light_layers_hash(image);
  if (exr::has_named_layers(image)) {
    const std::vector<float> total = exr::sum_of_lights(image);
    sum += exr::layer_hash(exr::LayerKind::Sum, total.data(), total.size());
  }
  sum += detail::reradiation_checksum(image);  // 0 without bispectral terms
  sum += detail::coefficients_checksum(image);  // 0 without spectral-basis coefficients
  sum += detail::guides_checksum(image);        // 0 without guide layers
  return exr::checksum_string(sum);
}

}  // namespace prizma::spectral
