#pragma once
// Writing a relit image: display transform (OpenColorIO) then OpenImageIO by extension, atomically.
//   .png          display-encoded, 8-bit (default) or 16-bit
//   .tif / .tiff  display-encoded, 8-bit or 16-bit
//   .jpg / .jpeg  display-encoded, 8-bit (quality 95)
//   .exr          linear float, no display transform: XYZ (channels X, Y, Z), or a linear colour
//                 space of the OCIO config (channels R, G, B) when colour_space is set
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "prizma/spectral/bin_layout.h"
#include "prizma/spectral/light_spectrum.h"
#include "prizma/spectral/relight_matrix.h"
#include "prizma/spectral/xyz_image.h"
#include "prizma/spectral/display.h"
#include "prizma/spectral/image_io.h"
#include "prizma/spectral/output_group.h"

namespace prizma::spectral {

enum class OutputFormat { Png, Tiff, Exr, Jpeg };

// Format from the extension (case-insensitive). Throws InputError (input `input`) for others.
OutputFormat output_format_for(const std::filesystem::path& path, const std::string& input = "--output");

// Image attributes written into the output ("prizma:lights", "prizma:exposureEV", …).
using ImageMetadata = std::vector<std::pair<std::string, std::string>>;

struct OutputOptions {
  DisplayOptions display;  // display, or colour_space for linear EXR output
  int bit_depth = 8;       // 8 or 16, PNG and TIFF only

  // Throws InputError(bit_depth_input, "must be 8 or 16 (got N)") for any other bit depth.
  void validate(const std::string& bit_depth_input = "bit depth") const;
};

// What a relit image records of how it was made: Software (`software`), prizma:source (the spectral
// EXR), prizma:lights (each layer's name and spec), the exposure, observer, units, adaptation, bin
// edges, and the display or linear colour space.
ImageMetadata relight_metadata(const std::string& software, const std::string& source,
                               const std::vector<std::string>& light_names, const std::vector<LightSpectrum>& lights,
                               const RelightOptions& relight, const OutputOptions& output, const BinLayout& bins);

// Checks, before any work, that `path` can be written: a known extension, an existing folder that
// is writable, and not a folder itself. Throws InputError (input `input`) naming the problem.
void check_output_path(const std::filesystem::path& path, const std::string& input = "--output");

// Display-encoded RGB of an XYZ image: a copy through the transform, clamped to [0, 1] for
// integer outputs by the caller. Non-finite values become 0.
std::vector<float> to_display(const XyzImage& image, const DisplayTransform& display);

// The display options a format uses: PNG/TIFF/JPEG the display (colour_space cleared); EXR the linear
// colour space, or none (XYZ written as is) when colour_space is empty.
bool needs_transform(OutputFormat format, const OutputOptions& opts);
DisplayOptions transform_options(OutputFormat format, const OutputOptions& opts);

// Checks the options a format needs (builds the transform once); throws InputError when the config,
// display or colour space does not exist, the bit depth is not 8 or 16 (validate("--bit-depth")), or
// a JPEG's is not 8.
void check_output_options(OutputFormat format, const OutputOptions& opts);

// The colour space a display transform encodes into, for the ICC profile of PNG/TIFF/JPEG outputs,
// found from the OCIO transform itself (DisplayTransform::split_matrix_curve): the primaries and
// white from its XYZ → linear RGB matrix, the decoding curve by inverting its per-channel curve,
// written as the standard parametric curve it matches (the sRGB piecewise curve, a 2.4 or 2.2
// power; within 2e-4) or else as a 1024-entry table. Nothing when the transform is not a matrix
// followed by one increasing curve for all channels from 0 to 1 (e.g. a 3D LUT display).
std::optional<PictureColourSpace> display_colour_space(const DisplayTransform& transform,
                                                                 const std::string& name);

// Writes the image (display transform for PNG/TIFF; for EXR only when colour_space is set).
// Written atomically, or into `group` (the run's outputs, appearing at its commit()); throws
// InputError (naming `input`) for bad paths (check_output_path) or options, RuntimeError (naming the
// path and OpenImageIO's message) for write failures.
void write_output_image(const std::filesystem::path& path, const XyzImage& image, const OutputOptions& opts,
                        const ImageMetadata& metadata, const std::string& input = "--output",
                        OutputGroup* group = nullptr);

}  // namespace prizma::spectral
