#pragma once
// The guide layers' part of reading and writing the spectral EXR (docs/spectral-exr.md, "Guide
// layers"): per guide plane a float channel guide.<name> and, when it has one, its variance of the
// mean guide.<name>.var. Light-independent per-pixel data the renderer writes for the denoiser
// (prizma-render --features); their names never match the layout's T.<λ> pattern, so a reader of
// the published layout (JCGT 2021) passes over them as extra channels, never as spectra.
#include <ImathBox.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>

#include <cstdint>
#include <string>

#include "prizma/spectral/spectral_exr.h"

namespace prizma::spectral::detail {

// True (with the guide's name and whether it is the variance channel) for guide.<name>[.var].
bool parse_guide_channel(const std::string& channel, std::string& name, bool& variance);

// Writing: validates image.guides (names of letters, digits and '_', each once; width·height values,
// variance empty or as many; finite values, variances ≥ 0: InputError(path, …)), adds their float
// channels and slices (pointing into image.guides) and returns their checksum terms (0: none).
std::uint64_t add_guides_for_write(const SpectralImage& image, Imf::Header& header, Imf::FrameBuffer& fb,
                                   const std::string& path);

// Reading: image.guides from the header's guide channels (sorted by name), with slices into them.
// Refuses a variance channel without its guide. After the read, check_guides_finite.
void add_guides_for_read(const Imf::Header& header, SpectralImage& image, Imf::FrameBuffer& fb, const Imath::Box2i& dw,
                         const std::string& path);
void check_guides_finite(const SpectralImage& image, const std::string& path);

// The checksum terms of the guides as held in memory (0 without them).
std::uint64_t guides_checksum(const SpectralImage& image);

}  // namespace prizma::spectral::detail
