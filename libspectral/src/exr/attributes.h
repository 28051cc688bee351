#pragma once
// The spectral EXR's attributes (internal; docs/spectral-exr.md, "Attributes"): the layout version,
// the bin edges and the prizma: provenance, written and read in one place.
#include <ImfHeader.h>

#include <optional>
#include <string>
#include <vector>

#include "prizma/spectral/spectral_exr.h"

namespace prizma::spectral::exr {

// spectralLayoutVersion, prizma:binEdgesNm (+ its exact copy) and image.info's prizma: attributes
// (prizma:checksum aside). Throws InputError(path, …) for light records that do not describe the
// image's layers (the reader's check: check_light_records).
void put_attributes(Imf::Header& header, const SpectralImage& image, const std::string& path);

// The prizma: attributes (is_prizma when the header holds any). Throws InputError(path, …) for a
// value of the wrong form (a seed that is not a 64-bit integer, prizma:lights that is not records).
SpectralExrInfo read_attributes(const Imf::Header& header, const std::string& path);

const std::string* find_string_attr(const Imf::Header& h, const char* name);

// prizma:binEdgesNm in any numeric form OpenEXR holds; nullopt when absent.
std::optional<std::vector<double>> edges_attribute(const Imf::Header& h, const char* name, const std::string& p);

}  // namespace prizma::spectral::exr
