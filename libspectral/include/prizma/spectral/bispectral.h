#pragma once
// Bispectral (fluorescent) transport: the off-diagonal terms M[out][in] of a light layer's
// re-radiation matrix (docs/spectral-exr.md, "Bispectral channels"; docs/fluorescence.md). The
// diagonal M[i][i] is the ordinary transport layer; SpectralImage::reradiation lists the (in, out)
// bin pairs held and TransportLayer::reradiation their values.
#include <Eigen/Core>
#include <string>
#include <string_view>
#include <vector>

#include "prizma/spectral/colour_matching.h"
#include "prizma/spectral/light_spectrum.h"
#include "prizma/spectral/spectral_exr.h"

namespace prizma::spectral {

// "T.<in>nm.<out>nm" (six decimals, comma separator, as spectral_channel_name), with an optional
// layer prefix: the reference layout's re-radiation channel, excitation wavelength first.
std::string reradiation_channel_name(double in_nm, double out_nm, std::string_view layer = "");

// Refuses (InputError naming `input`) pairs out of range, on the diagonal, repeated or not sorted by
// (in, out), and lights whose reradiation is neither empty (only when there are no pairs) nor
// pixel_count()·pairs values.
void check_reradiation_layout(const SpectralImage& image, const std::string& input);

// The sorted distinct `in` bins of image.reradiation.
std::vector<int> reradiation_in_bins(const SpectralImage& image);

// Adds, for light `light`, Σ_in M[out][in]·e[in] over the off-diagonal pairs to radiance[pixel·n + out]
// (radiance: pixel_count()·n values). e: the light per bin, n values (bin averages).
void add_reradiated(const SpectralImage& image, int light, const std::vector<double>& e, std::vector<double>& radiance);

// Per pixel the 3×|in_bins| weights K[c][k] = Σ_out c_out(c, out)·M[out][in_bins[k]] of light `light`
// (pixel-major, then c, then k): relighting adds K·ē (ē the light's bin averages at in_bins) to XYZ,
// a 3×|in_bins| product per pixel whatever the number of pairs. c_out: 3×n, the colour matching
// functions integrated over each out bin.
std::vector<float> reradiation_colour_weights(const SpectralImage& image, int light,
                                              const Eigen::Matrix<double, 3, Eigen::Dynamic>& c_out,
                                              const std::vector<int>& in_bins);

// Per pair of image.reradiation, the XYZ that a unit M[out][in] adds under `light` (normalised as
// relight_weights normalises it, so a white has Y = 1 at scale 1, then times its scale): column q is
// C[:, out_q]·ē[in_q], C the CMFs integrated over each bin, ē the light's bin averages; 3 × pairs,
// zero for a light that is off. A pixel's re-radiated XYZ is Σ_q M_q·column q (the R, G, B preview
// channels of the spectral EXR and prizma-render --preview; prizma-relight goes through K instead).
Eigen::Matrix<double, 3, Eigen::Dynamic> reradiation_pair_xyz(const SpectralImage& image, const ColorMatching& cmf,
                                                              const LightSpectrum& light);

}  // namespace prizma::spectral
