#pragma once
// The bispectral channels' part of reading and writing the spectral EXR (used by spectral_exr.cpp;
// kept here so that the diagonal layout's code stays as it was).
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

struct ReradiationChannel {
  std::string layer;  // prefix before "T." ("" = top level)
  double in_nm = 0.0;
  double out_nm = 0.0;
  std::string name;   // full channel name
};

// True (and `out` filled) when `name` is a re-radiation channel [<layer>.]T.<λ>.<λ> (each number in
// any of the reference reader's units); throws InputError for a non-positive wavelength.
bool parse_reradiation_channel(const std::string& name, const std::string& path, ReradiationChannel& out);

// Buffers the frame buffer's slices point into until the file is written.
struct ReradiationBuffers {
  std::list<std::vector<float>> floats;
  std::list<std::vector<half>> halves;
};

// Writing: validates the image's bispectral part (sizes, pairs, finite values), adds its channels
// (per light layer when `multi`, plus their sum at top level; else top level) and slices, and
// returns the checksum contribution (of the values a reader gets back). Nothing when there are no pairs.
std::uint64_t add_reradiation_for_write(const SpectralImage& image, bool multi, bool half_out, Imf::Header& header,
                                        Imf::FrameBuffer& fb, ReradiationBuffers& keep, const std::string& path);

// Reading: fills image.reradiation and each light's buffer's slices from `channels`. `layers` holds
// each light's layer prefix in image.lights order; `lambdas` the diagonal channels' wavelengths (the
// bins). Channels of other layers (the top-level sum of a multi-light file, variance) are ignored.
void add_reradiation_for_read(const std::vector<ReradiationChannel>& channels, const std::vector<std::string>& layers,
                              const std::vector<double>& lambdas, SpectralImage& image, Imf::FrameBuffer& fb,
                              const Imath::Box2i& dw, const std::string& path);

// After reading: refuses NaN or Inf in the bispectral values.
void check_reradiation_finite(const SpectralImage& image, const std::string& path);

// The checksum contribution of the bispectral values as held in memory.
std::uint64_t reradiation_checksum(const SpectralImage& image);

}  // namespace prizma::spectral::detail
