#pragma once
// The spectral OpenEXR layout (docs/spectral-exr.md; Fichet, Pacanowski, Wilkie, JCGT 2021):
// reflective channels T.<centre>nm, one layer per light (<light>.T.<centre>nm) when there are two
// or more lights, exact bin edges and provenance in prizma: attributes.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "prizma/spectral/bin_layout.h"
#include "prizma/spectral/light_record.h"

namespace prizma::spectral {

class OutputGroup;

struct SpectralExrInfo {
  // prizma:lights, one record per light (light_record.h). Written as given; when empty, records that
  // name the layers. Read: refused unless they describe the file's layers (check_light_records).
  std::vector<LightRecord> light_records;
  std::int64_t samples = 0;      // prizma:samples, samples per pixel in this file
  std::string sample_range;      // prizma:sampleRange "A:B"
  std::uint64_t seed = 0;        // prizma:seed (any 64-bit seed: docs/spectral-exr.md)
  std::string scene_hash;        // prizma:sceneHash
  std::string version;           // prizma:version
  std::string wavelength_sampling;  // prizma:wavelengthSampling
  // prizma:misLaneGroups: spectral MIS's lane groups (paths per sample) the samples were traced with;
  // 0: not recorded (a file without spectral MIS, or written before lane groups: one group).
  int mis_lane_groups = 0;
  std::string scene_path;        // prizma:scenePath, the scene file (absolute) the render read
  std::string render_options;    // prizma:renderOptions (JSON object: the command-line overrides)
  // prizma:denoised (JSON object: method, parameters, guides, variance, version; docs/denoise.md), or
  // empty: the values are the raw Monte Carlo means. denoised_summary() says it in words.
  std::string denoised;
  bool is_prizma = false;        // read: the file carried prizma: attributes
  // Read: what the reader inferred or adjusted that a careful user may want to know (an inferred bin
  // edge clamped to the colour matching tables); the tools print these with -v. Never written.
  std::vector<std::string> notes;
};

// How well a layer's k-term spectral-basis reconstruction relights under one test light
// (spectral_basis.h, choose_basis_size): CIEDE2000 against the exact relight over the pixels.
struct BasisError {
  std::string light;
  double percentile = 0.0;  // ΔE00 at the criterion's percentile (99th by default)
  double max = 0.0;         // largest ΔE00 over the evaluated pixels
};

// A light layer's compressed transport (docs/spectral-exr.md, "Spectral-basis coefficients"): k
// orthonormal basis spectra over the bins and k coefficients per pixel, t_p ≈ Σ_j c(p, j)·b_j.
// k = 0: the layer has none.
struct LayerCoefficients {
  int k = 0;
  std::vector<float> basis;        // k·bins: basis vector j is basis[j·bins, (j+1)·bins)
  std::vector<float> values;       // pixel_count·k, pixel-major: c(p, j) = values[p·k + j]
  std::vector<BasisError> errors;  // measured when k was chosen (empty when unknown)
};

// One light's transport: width·height·bins floats, pixel-major, bins contiguous:
// value(x, y, i) = data[(y·width + x)·bins + i].
struct TransportLayer {
  std::string name;              // light name; letters, digits, '_' and '-'
  std::vector<float> data;
  std::vector<float> variance;   // empty or same size: per-pixel variance of the mean
  // Bispectral (fluorescence) terms M[out][in], in ≠ out, for the pairs SpectralImage::reradiation
  // lists: empty, or pixel_count()·reradiation.size() floats, pixel-major, pairs contiguous
  // (docs/spectral-exr.md, "Bispectral channels"). The diagonal M[i][i] is `data`.
  std::vector<float> reradiation;
  // Spectral-basis coefficients, read only with ExrReadOptions::read_coefficients and written when
  // k > 0. In a compact file (SpectralImage::compact()) `data` and `variance` are empty.
  LayerCoefficients coefficients;
};

// A light-independent per-pixel plane the renderer writes for the denoiser (prizma-render --features;
// docs/spectral-exr.md, "Guide layers"): channels guide.<name> and guide.<name>.var.
struct GuideLayer {
  std::string name;              // letters, digits and '_': "depth", "scatter"
  std::vector<float> value;      // width·height floats, row-major: the per-pixel Monte Carlo mean
  std::vector<float> variance;   // empty or same size: its variance of the mean
  bool operator==(const GuideLayer&) const = default;
};

// A bispectral term: light absorbed in bin `in` re-emitted into bin `out` (in ≠ out).
struct BinPair {
  int in = 0;
  int out = 0;
  bool operator==(const BinPair&) const = default;
};

struct SpectralImage {
  int width = 0;
  int height = 0;
  BinLayout bins;
  std::vector<TransportLayer> lights;  // at least one
  SpectralExrInfo info;
  // The bispectral pairs every light's `reradiation` holds, sorted by (in, out); empty for a
  // wavelength-diagonal image (no fluorescence), which is then written exactly as before.
  std::vector<BinPair> reradiation;

  // Guide layers (renders with --features), in the order written; empty for most files.
  std::vector<GuideLayer> guides;

  // How the layers' coefficients were chosen (prizma:coefficients "criterion", a JSON object), or empty.
  std::string coefficient_criterion;

  std::size_t pixel_count() const { return static_cast<std::size_t>(width) * height; }
  // Every layer carries coefficients.
  bool has_coefficients() const;
  // Coefficients only, no transport bins (written by prizma-relight compress --compact).
  bool compact() const;
  // Index of the light with this name, or -1.
  int find_light(std::string_view name) const;
};

enum class ExrPixelType {
  Float,  // default
  Half,   // only on request; values beyond half's range are refused (or clamped, see below)
};

struct ExrWriteOptions {
  ExrPixelType pixel_type = ExrPixelType::Float;
  // With Half: clamp values above 65504 and warn on stderr, instead of refusing.
  bool clamp_half = false;
  bool write_variance = true;  // write var layers where present
  // Preview channels R, G, B: the default relight (each light's recorded spectrum, CIE 1931) in linear
  // sRGB, for viewers that do not read spectra. Not covered by the checksum; readers ignore them.
  bool write_preview = true;
  // Threads encoding the file's chunks: 0 = OpenEXR's global pool (the cores, at most 8); 1 = all in
  // the calling thread (prizma-render --threads 1); n = at most n chunks in flight. The file is the
  // same byte for byte whatever the count.
  int threads = 0;
  // Written into this group of the run's outputs (output_group.h), to appear at its commit(); null:
  // in place when this call returns.
  OutputGroup* group = nullptr;
};

// Writes atomically (temporary file in the same folder, then rename): a failure never leaves a partial
// file and never destroys an existing one. Throws InputError for invalid images (NaN, names),
// RuntimeError for I/O failures, naming the path.
void write_spectral_exr(const std::filesystem::path& path, const SpectralImage& image,
                        const ExrWriteOptions& opts = {});

// Reads a Prizma file or any conforming single-layer reflective spectral EXR (bin edges then derived
// at midpoints between centres, first and last bins mirrored). Throws InputError naming the path
// for files that are not EXR, truncated, emissive-only, without spectral channels, or with
// inconsistent edges and centres.
//
// prizma:checksum is verified unless opts.verify_checksum is false: a mismatch is InputError "pixel
// data do not match prizma:checksum", saying when the header shows that another tool re-encoded the
// file (half, PXR24, B44: the values changed, the attribute was copied), and naming
// opts.unverified_read, the caller's way to read the file anyway.
//
// Spectral-basis coefficients (docs/spectral-exr.md): read into TransportLayer::coefficients only
// with read_coefficients (else their channels are read only to verify the checksum). A compact
// file (coefficients, no bins) is refused with an InputError that says so unless allow_compact.
struct ExrReadOptions {
  bool verify_checksum = true;
  // How the user of the calling tool turns the check off, for the mismatch message ("--no-verify"
  // in every executable that reads spectral EXR files; "verify=False" in Python).
  std::string unverified_read = "--no-verify";
  bool read_coefficients = false;
  bool allow_compact = false;
};
SpectralImage read_spectral_exr(const std::filesystem::path& path, const ExrReadOptions& opts = {});

// The prizma:checksum value of an image as held in memory (what read_spectral_exr returns): every
// light's transport and variance values and, with two or more lights, their sum, the top-level T
// layer (docs/spectral-exr.md gives the definition). A float file's stored checksum equals this for
// the image read from it (a half file's holds the sum rounded to half).
std::string spectral_pixel_checksum(const SpectralImage& image);

// What prizma:denoised records, as the readers show it ("denoised by prizma 0.5: non-local means on
// luminance, depth; variance propagated"), or "" for a raw file. Never throws: a record it cannot
// parse is shown as "denoised (prizma:denoised unreadable)".
std::string denoised_summary(const SpectralExrInfo& info);

// "T.550,000000nm" style channel name for a wavelength (six decimals, comma separator).
std::string spectral_channel_name(double lambda_nm, std::string_view layer = "");

// What write_spectral_exr refuses, checkable before the work that makes the image. A light name
// must be letters, digits, '_' and '-' and not "var" (the variance layers' name); every bin needs
// its own channel name (centres that differ in the six decimals). Throw InputError(input, …).
void check_exr_light_name(std::string_view name, const std::string& input);
void check_exr_bin_names(const BinLayout& bins, const std::string& input);

}  // namespace prizma::spectral
