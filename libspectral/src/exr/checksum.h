#pragma once
// prizma:checksum (internal; docs/spectral-exr.md): the pixel values as a reader gets them, hashed per
// layer kind (exr_common.h's table) and summed, and its check on reading.
#include <ImfHeader.h>

#include <cstdint>
#include <string>
#include <vector>

#include "exr/exr_common.h"
#include "prizma/spectral/fnv1a.h"
#include "prizma/spectral/spectral_exr.h"

namespace prizma::spectral::exr {

// Checksum versions (the value's prefix): v2 also covers the top-level T layer of a file with two or
// more lights (the sum of the lights); v1, written before it, covers the light and variance layers.
inline constexpr const char* kChecksumScheme = "fnv1a64-words-v2:";
inline constexpr const char* kChecksumSchemeV1 = "fnv1a64-words:";

// One layer's term: FNV-1a over n values (float or half; one 32-bit word each) from its kind's
// offset basis. The terms are summed modulo 2⁶⁴ by the caller, so their order does not matter.
template <class Value>
std::uint64_t layer_hash(LayerKind kind, const Value* values, std::size_t n) {
  Fnv1a h(layer_kind(kind).checksum_basis);
  h.add_float_words(values, n);
  return h.value();
}

std::string checksum_string(std::uint64_t sum, const char* scheme = kChecksumScheme);

// The top-level T layer of a file with two or more lights: per value the float of the double sum over
// the lights (what the writer stores).
std::vector<float> sum_of_lights(const SpectralImage& image);

// prizma:checksum against the pixels read: v2 with the top-level layer `top` (null when the file has
// none, or one light), v1 without it. InputError(p, …) on a mismatch, saying when the header shows
// that another tool re-encoded the file, and naming `unverified_read`.
void verify_checksum(const std::string& p, const Imf::Header& header, const std::string& stored,
                     const SpectralImage& image, const std::vector<float>* top, const std::string& unverified_read);

}  // namespace prizma::spectral::exr
