#pragma once
// What the parts of the spectral EXR layer share (libspectral/src/exr/, internal; docs/spectral-exr.md):
// the attribute names, the kinds of layers a file holds with their checksum terms, OpenEXR's thread
// pool and the compression Prizma writes.
#include <ImfCompression.h>
#include <ImfHeader.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "prizma/spectral/fnv1a.h"
#include "prizma/spectral/spectral_exr.h"

namespace prizma::spectral::exr {

inline constexpr const char* kLayoutVersion = "1.0";
inline constexpr const char* kAttrEdges = "prizma:binEdgesNm";
// The same edges as decimal text with 17 significant digits: the float vector above loses the
// double precision of BinLayout, this restores it exactly (readers that do not know it ignore it).
inline constexpr const char* kAttrEdgesExact = "prizma:binEdgesNmExact";
inline constexpr const char* kAttrLights = "prizma:lights";
inline constexpr const char* kAttrSamples = "prizma:samples";
inline constexpr const char* kAttrSampleRange = "prizma:sampleRange";
inline constexpr const char* kAttrSeed = "prizma:seed";
inline constexpr const char* kAttrSceneHash = "prizma:sceneHash";
inline constexpr const char* kAttrVersion = "prizma:version";
inline constexpr const char* kAttrWavelengthSampling = "prizma:wavelengthSampling";
inline constexpr const char* kAttrMisLaneGroups = "prizma:misLaneGroups";
inline constexpr const char* kAttrChecksum = "prizma:checksum";
inline constexpr const char* kAttrScenePath = "prizma:scenePath";
inline constexpr const char* kAttrRenderOptions = "prizma:renderOptions";
inline constexpr const char* kAttrDenoised = "prizma:denoised";
inline constexpr const char* kVarianceLayer = "var";
inline constexpr float kHalfMax = 65504.0f;

// The kinds of channel sets a Prizma file holds (docs/spectral-exr.md), each with its term of
// prizma:checksum: FNV-1a 64 over the values as a reader gets them (prizma/spectral/fnv1a.h, the
// scene hash's FNV-1a too) from the kind's own offset basis, the terms summed modulo 2⁶⁴. One row per kind, so a new kind (the denoiser's guide
// layers) is a row here and its own reader and writer, not a branch in every loop.
enum class LayerKind : unsigned char {
  Transport,     // a light's bins (T.<λ>nm, or <light>.T.<λ>nm)
  Sum,           // the top-level T layer of a file with two or more lights: their sum (v2 checksum)
  Variance,      // a light's variance of the mean ([<light>.]var.T.<λ>nm)
  Bispectral,    // a light's re-radiation pairs M[out][in] ([<light>.]T.<λin>nm.<λout>nm; bispectral.cpp)
  Coefficients,  // a light's spectral-basis coefficients ([<light>.]coef.<j>; coefficients_exr.cpp)
  Basis,         // the basis vectors of those coefficients (prizma:basis.<light>)
  Guide,         // a guide plane of the denoiser (guide.<name>; guides_exr.cpp)
  GuideVariance, // its variance of the mean (guide.<name>.var)
  Preview,       // R, G, B: the default relight in linear sRGB, derived, outside the checksum
};
struct LayerKindInfo {
  LayerKind kind;
  const char* name;             // in messages
  std::uint64_t checksum_basis;  // FNV-1a offset basis of its checksum term; 0: not in the checksum
};
inline constexpr LayerKindInfo kLayerKinds[] = {
    {LayerKind::Transport, "light", kFnv1aOffsetBasis},  // 0xcbf29ce484222325; the others are it rotated
    {LayerKind::Sum, "sum of all lights", 0xe4842223cbf2925cULL},
    {LayerKind::Variance, "variance of light", 0x84222325cbf29ce4ULL},
    {LayerKind::Bispectral, "bispectral terms of light", 0x2325cbf29ce48422ULL},
    {LayerKind::Coefficients, "coefficients of light", 0x9ce484222325cbf2ULL},
    {LayerKind::Basis, "basis of light", 0x484222325cbf29ceULL},
    {LayerKind::Guide, "guide", 0x2223cbf29ce48425ULL},
    {LayerKind::GuideVariance, "variance of guide", 0xf29ce4842223cb25ULL},
    {LayerKind::Preview, "preview", 0},
};
constexpr const LayerKindInfo& layer_kind(LayerKind k) {
  for (const LayerKindInfo& info : kLayerKinds)
    if (info.kind == k) return info;
  return kLayerKinds[0];  // unreachable: every kind has a row
}

// A file holds a layer per light, named after it, and their sum at top level for readers of the
// published layout, when it has two or more lights or bispectral terms (the top level then holds the
// layout's re-radiation pairs, which cannot hold all of Prizma's: bispectral.cpp); else its one
// light is the top level.
inline bool has_named_layers(const SpectralImage& image) { return image.lights.size() >= 2 || !image.reradiation.empty(); }

// Threads for compressing and decompressing chunks (starts OpenEXR's global pool on first use).
int io_threads();
// Pixel data of at most this many bytes (all channels, as stored) are written uncompressed, larger
// images with PIZ (docs/spectral-exr.md, "Compression").
std::size_t stored_pixel_bytes(const Imf::Header& h);
Imf::Compression prizma_compression(const Imf::Header& h);

// A light name: letters, digits, '_' and '-'.
bool valid_light_name(std::string_view name);
inline std::string layer_prefix(std::string_view layer) { return layer.empty() ? std::string() : std::string(layer) + "."; }

// Refuses a NaN or infinite value of a pixel-major, bin-contiguous buffer, naming pixel and bin.
void check_finite(const std::vector<float>& values, int width, int bins, const std::string& what,
                  const std::string& path);

}  // namespace prizma::spectral::exr
