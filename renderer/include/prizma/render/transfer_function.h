#pragma once
// TransferFunction: how volume values become materials. A list of rules (value range → material,
// first match wins, density ramp over the value) over a list of materials; built from the scene's
// "materials" or imported from a VPT-style transfer-function image. build_medium() applies it to a
// Volume and gives the Medium the tracer sees.
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "prizma/render/material_rule.h"
#include "prizma/render/scene.h"
#include "prizma/render/volume.h"

namespace prizma::render {

struct TransferFunction {
  std::vector<Material> materials;
  std::vector<MaterialRule> rules;
};

// Maps raw values to [0, 1]: t = (v − min)/(max − min), clamped.
struct ValueNormalisation {
  double min = 0.0;
  double max = 1.0;
  double to_unit(double v) const;
  double from_unit(double t) const { return min + t * (max - min); }
};

// min/max over the finite values of `vol` (max = min + 1 when the volume is constant, so the map
// stays defined). Throws InputError when the volume has no finite value.
ValueNormalisation auto_normalisation(const Volume& vol);

// Checks a material's spectra: albedo in [0, 1], extinction ≥ 0, |g| < 1 (all table values and
// constants). Throws InputError with input `input` + ".albedo" (etc.) naming the offending value.
void validate_material(const Material& m, const std::string& input);

// Reads a VPT-style transfer-function image with OpenImageIO: x = wavelength (pixel centres spread
// over [lambda_lo_nm, lambda_hi_nm]), y = normalised value (row 0 = top scanline = value 0, row
// height−1 = value 1); R = albedo, G = extinction as a fraction of `extinction_scale` (per scene
// unit), B = anisotropy with g = 2B − 1 (clamped to ±0.999). Each distinct row whose G is not all
// zero becomes a Material ("row<y>"); runs of rows become rules over the raw-value ranges that map
// to them through `norm`; rows with G all zero are empty space. `input` names the image in errors.
TransferFunction read_transfer_function_image(const std::filesystem::path& image, double extinction_scale,
                                              double lambda_lo_nm, double lambda_hi_nm,
                                              const ValueNormalisation& norm, const std::string& input);

// Applies the rules to every voxel (material index, or Medium::kEmpty when no rule matches or the
// value is not finite; density = the rule's ramp at the value) and sets the world box: extents
// dims × spacing scaled so the largest side is 1, centred at the origin. With Trilinear the medium
// also keeps the raw values and the rules, and the tracer classifies the value interpolated at each
// point (post-classification). Throws InputError (input `input`) with more than 65534 materials or
// a rule naming a missing material.
Medium build_medium(const Volume& vol, const TransferFunction& tf, const std::string& input,
                    Interpolation interpolation = Interpolation::Nearest);

}  // namespace prizma::render
