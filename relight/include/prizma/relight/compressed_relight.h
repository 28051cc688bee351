#pragma once
// Compressed transport (docs/relight.md, "Compressed transport"): each light layer as k spectral
// basis coefficients per pixel (libspectral's spectral_basis.h), relit with a 3×k matrix per light,
// W_l = M_l·B_l, instead of 3×n; and DisplayEncoder8, the XYZ → 8-bit display step with the OCIO
// transform's matrix applied directly and its per-channel curve baked into exact code thresholds.
#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "prizma/spectral/relight_matrix.h"
#include "prizma/spectral/xyz_image.h"
#include "prizma/spectral/display.h"
#include "prizma/spectral/spectral_basis.h"
#include "prizma/spectral/spectral_exr.h"

namespace prizma::relight {

// One light layer: t_p ≈ basis·c_p. The coefficients are IEEE binary16 ("half", what the spectral
// EXR's coefficient channels hold): half the bytes of float for the relight to read. To keep half's
// precision whatever the transport's level, the layer is scaled by a power of two 2^e chosen so that
// the largest |c| lies in [16384, 32768) (half's largest finite is 65504): the coefficients are
// c/2^e and the basis columns, orthogonal, each have length 2^e (exact in float either way).
struct CompressedLayer {
  std::string name;
  int k = 0;
  Eigen::MatrixXf basis;                     // n×k, orthogonal columns of length 2^e
  std::vector<std::uint16_t> coefficients;   // pixels·k half bits, pixel-major: c(p, j) at [p·k + j]
  std::vector<spectral::BasisError> errors;  // at k, under the criterion's lights, of these half
                                             // coefficients (empty if unknown)
};

// The layer from float coefficients (pixels·k, pixel-major) and their n×k basis (orthonormal from
// the projection; as stored when read from a file): the power-of-two scale above (1 when the
// coefficients are already in range), then each coefficient rounded to the nearest half (ties to
// even). Throws RuntimeError for a non-finite coefficient.
void set_half_coefficients(CompressedLayer& layer, const Eigen::MatrixXf& basis, const std::vector<float>& coefficients);

// t_p = basis·c_p of pixel p (n floats).
Eigen::VectorXf reconstructed_spectrum(const CompressedLayer& layer, std::size_t p);

struct CompressedTransport {
  int width = 0;
  int height = 0;
  spectral::BinLayout bins;
  std::vector<CompressedLayer> lights;
  std::size_t pixel_count() const { return static_cast<std::size_t>(width) * height; }
};

// Per light: basis from the layer's Gram matrix, k by choose_basis_size, coefficients by projection,
// stored as half (set_half_coefficients); the errors are those of the half coefficients, and k grows
// by one while half rounding takes an error past the criterion's bound.
CompressedTransport compress_transport(const spectral::SpectralImage& image,
                                       const spectral::BasisCriterion& criterion = {});

// The coefficients a spectral EXR carries (SpectralImage::has_coefficients; read with
// ExrReadOptions::read_coefficients), moved out of the image's layers as half (their k, basis and
// errors stay; set_half_coefficients, so a file of float coefficients is scaled and rounded here).
// Throws InputError (naming `source`) when a layer's sizes disagree.
CompressedTransport take_coefficients(spectral::SpectralImage& image, const std::string& source);

// Stores `transport` in the image's layers for write_spectral_exr (coefficients, basis, errors and the
// criterion); with `compact` the transport bins and variance are dropped.
void store_coefficients(spectral::SpectralImage& image, const CompressedTransport& transport,
                        const spectral::BasisCriterion& criterion, bool compact);

// The criterion as the JSON object prizma:coefficients records ("criterion").
std::string criterion_json(const spectral::BasisCriterion& criterion);

// prizma-relight compress: reads `input` (bins required: a compact file is refused, and so is a
// bispectral one), compresses every layer with `criterion` and writes `output` atomically with the
// coefficients added (the bins kept unless `compact`). Returns what was stored (per layer k and errors).
struct CompressFileOptions {
  bool compact = false;
  bool verify_checksum = true;
  spectral::BasisCriterion criterion;
};
CompressedTransport compress_spectral_exr(const std::filesystem::path& input, const std::filesystem::path& output,
                                          const CompressFileOptions& options);

// The weights relight_compressed_into multiplies each light's coefficients by: W_l = M_l·B_l, 3×k_l
// as float, row-major (X, Y, Z rows); empty for a light that is off. The live page's shader uses these
// very numbers. Throws as relight_compressed_into when the matrix does not match the transport.
std::vector<std::vector<float>> coefficient_weights(const CompressedTransport& transport, const spectral::RelightMatrix& matrix);

// XYZ = Σ_l (M_l·B_l)·c_l for every pixel (TBB over rows; independent of the thread count). Throws
// RuntimeError when the matrix does not match the transport's lights or bins, or a layer's sizes
// are inconsistent.
void relight_compressed_into(const CompressedTransport& transport, const spectral::RelightMatrix& matrix,
                             float* xyz_out);
spectral::XyzImage relight_compressed(const CompressedTransport& transport, const spectral::RelightMatrix& matrix);

class DisplayEncoder8;

// One frame from coefficients straight to 8-bit display RGB (3·pixels bytes, interleaved): the
// display matrix folded into the 3×k weights (A·M_l·B_l), each block of pixels relit to linear RGB in
// registers and encoded through the encoder's step table (TBB over rows, Highway SIMD over pixels).
// The codes equal encoder.encode(relight_compressed_into(...)) within one (float rounding of the
// folded matrix), and do not depend on the thread count. Needs a baked encoder with a step table;
// otherwise it relights to XYZ and calls encode() (same codes, slower).
void relight_compressed_to_display8(const CompressedTransport& transport, const spectral::RelightMatrix& matrix,
                                    const DisplayEncoder8& encoder, std::uint8_t* rgb_out);

// XYZ → 8-bit display RGB, the values spectral::write_output_image writes into an 8-bit PNG (OCIO transform,
// clamp to [0, 1], round to 255ths), computed fast when the transform is a matrix followed by a
// per-channel curve (DisplayTransform::split_matrix_curve): the curve is baked into the 255 exact
// linear thresholds between codes per channel, found by bisection on the curve itself, with a
// 32768-entry table per channel indexed by a float's top 16 bits for a first guess (and, for the
// fused frame, the step table below: one read per code). The baked form
// is checked against the full transform on 4096 colours at construction; where the split does not
// exist or the check fails, encode() runs the OCIO transform itself.
class DisplayEncoder8 {
 public:
  explicit DisplayEncoder8(const spectral::DisplayTransform& display);
  bool baked() const { return m_baked; }
  // Baked: the display matrix (XYZ → linear display RGB) and the curve as code thresholds.
  const Eigen::Matrix3f& matrix() const { return m_matrix; }
  // The step table (baked curves with at most one code step in any bucket of 2^shift float bit
  // patterns; empty otherwise): one 32-bit entry per bucket and channel holding both the code of the
  // bucket's first value and where in the bucket the next step lies, so that a code is one table read
  // and one integer compare, exact (no float rounding). For a linear value v, its bits b (as int32)
  // clamped to [lo_bits, hi_bits] and i = (b >> shift) − base:
  //   code = (entries[c][i] & 255) + ((b & (2^shift − 1)) ≥ (entries[c][i] >> 8)),
  // where entries[c][i] >> 8 is 2^shift when no step lies inside the bucket. Values below lo_bits
  // (negatives included) take the code of 0; values above hi_bits the code of the largest threshold.
  struct StepTable {
    std::array<std::vector<std::uint32_t>, 3> entries;
    int shift = 0;
    std::int32_t base = 0, lo_bits = 0, hi_bits = 0;
    bool empty() const { return entries[0].empty(); }
    // The code of linear v by the formula above, one value at a time (the fused frame's kernel is
    // its SIMD form); the table must not be empty.
    std::uint32_t code(int channel, float v) const;
  };
  const StepTable& step_table() const { return m_steps; }
  // thresholds(c)[j]: the smallest linear value with code ≥ j (j = 1..255), [256] = +∞.
  const float* thresholds(int channel) const { return m_thresholds[static_cast<std::size_t>(channel)].data(); }
  // xyz: 3·pixels floats, interleaved; rgb: 3·pixels bytes. Non-finite values count as 0.
  void encode(const float* xyz, std::size_t pixels, std::uint8_t* rgb) const;

 private:
  void encode_chunk(const float* xyz, std::size_t pixels, std::uint8_t* rgb) const;
  void build_step_table();
  const spectral::DisplayTransform* m_display;
  bool m_baked = false;
  Eigen::Matrix3f m_matrix = Eigen::Matrix3f::Identity();
  // Per channel: m_thresholds[c][j] = smallest linear value with code ≥ j (j = 1..255; [0] unused,
  // [256] = +∞).
  std::array<std::array<float, 257>, 3> m_thresholds{};
  std::array<std::vector<std::uint8_t>, 3> m_guess;  // code of the smallest value of each 16-bit bucket
  StepTable m_steps;
};

}  // namespace prizma::relight
