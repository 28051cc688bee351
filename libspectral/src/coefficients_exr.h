#pragma once
// The spectral-basis coefficients' part of reading and writing the spectral EXR (used by
// spectral_exr.cpp; docs/spectral-exr.md, "Spectral-basis coefficients"): per light layer k channels
// [<light>.]coef.<j>, the basis as the float vector prizma:basis.<light> and prizma:coefficients
// (JSON: k and the measured ΔE00 per light, the criterion).
#include <ImathBox.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>

#include <half.h>

#include <cstdint>
#include <list>
#include <string>
#include <vector>

#include "prizma/spectral/spectral_exr.h"

namespace prizma::spectral::detail {

struct CoefficientChannel {
  std::string layer;  // prefix before "coef." ("" = top level)
  int index = 0;      // j
  std::string name;   // full channel name
};

// True (and `out` filled) when `name` is a coefficient channel [<layer>.]coef.<j>.
bool parse_coefficient_channel(const std::string& name, CoefficientChannel& out);

// Writing: validates the layers' coefficients (all layers or none, sizes, finite values within
// half's range), adds the half channels (per light layer when `multi`, else top level), their
// slices (the values rounded to half into `buffers`, which must outlive the write) and the
// attributes, and returns the checksum contribution. Nothing (0) when no layer has coefficients.
std::uint64_t add_coefficients_for_write(const SpectralImage& image, bool multi, Imf::Header& header,
                                         Imf::FrameBuffer& fb, const std::string& path,
                                         std::list<std::vector<half>>& buffers);

// Reading: for each light (image.lights, already named; `layers` their channel prefixes in the same
// order) finds its coefficient channels, reads its basis from the header and adds slices into
// image.lights[l].coefficients. `bins` is the bin count. Refuses channels of no light, lights
// without them when others have them, gaps in the numbering, a missing or mis-sized basis and a
// prizma:coefficients that disagrees. Nothing when `channels` is empty.
void add_coefficients_for_read(const std::vector<CoefficientChannel>& channels, const Imf::Header& header,
                               const std::vector<std::string>& layers, int bins, SpectralImage& image,
                               Imf::FrameBuffer& fb, const Imath::Box2i& dw, const std::string& path);

// After reading: refuses NaN or Inf in the coefficients.
void check_coefficients_finite(const SpectralImage& image, const std::string& path);

// The checksum contribution of the coefficients and bases as held in memory (0 without them).
std::uint64_t coefficients_checksum(const SpectralImage& image);

}  // namespace prizma::spectral::detail
