#include "prizma/spectral/output_image.h"

#include <Eigen/Dense>
#include <nlohmann/json.hpp>
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <memory>
#include <optional>
#include <sstream>
#include <vector>

#include "prizma/spectral/atomic_file.h"
#include "prizma/spectral/output_group.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/image_io.h"
#include "prizma/spectral/light_record.h"

namespace prizma::spectral {

namespace fs = std::filesystem;

OutputFormat output_format_for(const fs::path& path, const std::string& input) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".png") return OutputFormat::Png;
  if (ext == ".tif" || ext == ".tiff") return OutputFormat::Tiff;
  if (ext == ".exr") return OutputFormat::Exr;
  if (ext == ".jpg" || ext == ".jpeg") return OutputFormat::Jpeg;
  throw InputError(input, "unknown output format \"" + path.string() + "\" (known: .png, .tif, .tiff, .jpg, .jpeg, .exr)");
}

void check_output_path(const fs::path& path, const std::string& input) {
  output_format_for(path, input);
  check_output_file(path, input);
}

bool needs_transform(OutputFormat format, const OutputOptions& opts) {
  return format != OutputFormat::Exr || !opts.display.colour_space.empty();
}

DisplayOptions transform_options(OutputFormat format, const OutputOptions& opts) {
  DisplayOptions d = opts.display;
  if (format != OutputFormat::Exr) d.colour_space.clear();
  return d;
}

ImageMetadata relight_metadata(const std::string& software, const std::string& source,
                               const std::vector<std::string>& light_names, const std::vector<LightSpectrum>& lights,
                               const RelightOptions& relight, const OutputOptions& output, const BinLayout& bins) {
  std::vector<LightRecord> records;
  for (std::size_t l = 0; l < light_names.size() && l < lights.size(); ++l)
    records.push_back(light_record(light_names[l], lights[l].text));
  std::ostringstream exposure;
  exposure << relight.exposure_ev;
  ImageMetadata md = {
      {"Software", software},
      {"prizma:source", source},
      {"prizma:lights", light_records_json(records)},
      {"prizma:exposureEV", exposure.str()},
      {"prizma:cmf", observer_name(relight.cmf)},
      {"prizma:units", relight.units == LightUnits::Absolute ? "absolute" : "relative-to-white"},
      {"prizma:adaptation", relight.adapt_to_d65 ? "bradford-to-D65" : "none"},
      {"prizma:binEdgesNm", bins.to_string()},
  };
  if (!output.display.colour_space.empty()) md.emplace_back("prizma:colourSpace", output.display.colour_space);
  md.emplace_back("prizma:display", output.display.display);
  return md;
}

void OutputOptions::validate(const std::string& bit_depth_input) const {
  if (bit_depth != 8 && bit_depth != 16)
    throw InputError(bit_depth_input, "must be 8 or 16 (got " + std::to_string(bit_depth) + ")");
}

void check_output_options(OutputFormat format, const OutputOptions& opts) {
  opts.validate("--bit-depth");
  if (format == OutputFormat::Jpeg && opts.bit_depth != 8) {
    throw InputError("--bit-depth", "JPEG is 8-bit only (got " + std::to_string(opts.bit_depth) + "; use .png or .tif for 16)");
  }
  if (needs_transform(format, opts)) DisplayTransform check(transform_options(format, opts));
}

std::vector<float> to_display(const XyzImage& image, const DisplayTransform& display) {
  std::vector<float> rgb(image.xyz);
  for (float& v : rgb)
    if (!std::isfinite(v)) v = 0.0f;
  display.apply(rgb.data(), image.pixel_count());
  return rgb;
}

namespace {

// The CIE xy chromaticities (red, green, blue, white) of the RGB space `xyz_to_rgb` converts XYZ
// into: the columns of its inverse are the primaries' XYZ, the inverse times (1, 1, 1) the white's.
// Nothing for a singular matrix or a primary at infinity.
std::optional<std::array<double, 8>> chromaticities_of(const Eigen::Matrix3d& xyz_to_rgb) {
  if (!(std::abs(xyz_to_rgb.determinant()) > 1e-12)) return std::nullopt;
  const Eigen::Matrix3d inv = xyz_to_rgb.inverse();
  std::array<double, 8> out{};
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d xyz = k < 3 ? Eigen::Vector3d(inv.col(k)) : Eigen::Vector3d(inv * Eigen::Vector3d::Ones());
    const double sum = xyz.sum();
    if (!(std::abs(sum) > 1e-12)) return std::nullopt;
    out[static_cast<std::size_t>(2 * k)] = xyz[0] / sum;
    out[static_cast<std::size_t>(2 * k + 1)] = xyz[1] / sum;
  }
  return out;
}

// The EXR "chromaticities" (red, green, blue, white xy) of an EXR output: XYZ's own for XYZ (R, G, B
// hold X, Y, Z: red (1, 0), green (0, 1), blue (0, 0), white (⅓, ⅓), equal energy); for a
// linear colour space those that take its RGB back to the image's XYZ (the OCIO transform's matrix M,
// found from the XYZ unit vectors). Nothing for a colour space that is not linear.
std::optional<std::array<float, 8>> exr_chromaticities(const OutputOptions& opts) {
  if (opts.display.colour_space.empty()) return std::array<float, 8>{1, 0, 0, 1, 0, 0, 1.0f / 3, 1.0f / 3};
  const DisplayTransform transform(transform_options(OutputFormat::Exr, opts));
  std::array<float, 9> unit{1, 0, 0, 0, 1, 0, 0, 0, 1}, half{0.5f, 0, 0, 0, 0.5f, 0, 0, 0, 0.5f};
  transform.apply(unit.data(), 3);
  transform.apply(half.data(), 3);
  Eigen::Matrix3d m;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) {
      m(r, c) = unit[static_cast<std::size_t>(3 * c + r)];
      const double h = half[static_cast<std::size_t>(3 * c + r)];
      if (!(std::abs(2.0 * h - m(r, c)) <= 1e-5 * (1.0 + std::abs(m(r, c))))) return std::nullopt;  // not linear
    }
  const auto xy = chromaticities_of(m);
  if (!xy) return std::nullopt;
  std::array<float, 8> out{};
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = static_cast<float>((*xy)[i]);
  return out;
}

}  // namespace

std::optional<PictureColourSpace> display_colour_space(const DisplayTransform& transform,
                                                                 const std::string& name) {
  const std::optional<DisplayMatrixCurve> split = transform.split_matrix_curve();
  if (!split) return std::nullopt;
  const auto xy = chromaticities_of(split->matrix);
  if (!xy) return std::nullopt;
  PictureColourSpace cs;
  cs.name = name;
  cs.chromaticities = *xy;

  // The curve (linear → encoded), sampled at x = (k/K)³ (dense near black, where an encoding is
  // steepest), the same on the three channels, increasing from 0 to 1: then inverted into the
  // decoding table at evenly spaced encoded values.
  constexpr int kSamples = 16384;
  std::vector<float> rgb(static_cast<std::size_t>(3 * (kSamples + 1)));
  std::vector<double> linear(kSamples + 1), encoded(kSamples + 1);
  for (int k = 0; k <= kSamples; ++k) {
    const double t = static_cast<double>(k) / kSamples;
    linear[static_cast<std::size_t>(k)] = t * t * t;
    for (int c = 0; c < 3; ++c) rgb[static_cast<std::size_t>(3 * k + c)] = static_cast<float>(t * t * t);
  }
  split->curve(rgb.data(), kSamples + 1);
  for (int k = 0; k <= kSamples; ++k) {
    const float* p = &rgb[static_cast<std::size_t>(3 * k)];
    if (!(p[0] == p[1] && p[1] == p[2]) || !std::isfinite(p[0])) return std::nullopt;
    encoded[static_cast<std::size_t>(k)] = p[0];
    if (k > 0 && !(encoded[static_cast<std::size_t>(k)] >= encoded[static_cast<std::size_t>(k - 1)])) return std::nullopt;
  }
  if (!(std::abs(encoded.front()) < 1e-4 && std::abs(encoded.back() - 1.0) < 1e-4)) return std::nullopt;
  constexpr int kTable = 1024;
  std::vector<float> decode(kTable);
  for (int j = 0; j < kTable; ++j) {
    const double e = static_cast<double>(j) / (kTable - 1);
    const auto it = std::lower_bound(encoded.begin(), encoded.end(), e);
    double x = 1.0;
    if (it == encoded.begin()) {
      x = 0.0;
    } else if (it != encoded.end()) {
      const auto k = static_cast<std::size_t>(it - encoded.begin());
      const double f = (e - encoded[k - 1]) / std::max(encoded[k] - encoded[k - 1], 1e-300);
      x = linear[k - 1] + f * (linear[k] - linear[k - 1]);
    }
    decode[static_cast<std::size_t>(j)] = static_cast<float>(x);
  }
  // A standard curve is written in its exact parametric form (what viewers expect of sRGB, P3 and
  // BT.1886-style power laws); any other as the table.
  struct Candidate {
    int type;
    std::array<double, 5> params;
  };
  const Candidate candidates[] = {{4, {2.4, 1.0 / 1.055, 0.055 / 1.055, 1.0 / 12.92, 0.04045}},
                                  {1, {2.4, 0, 0, 0, 0}},
                                  {1, {2.2, 0, 0, 0, 0}}};
  for (const Candidate& c : candidates) {
    double worst = 0.0;
    for (int j = 0; j < kTable; ++j) {
      const double v = static_cast<double>(j) / (kTable - 1);
      const double l = c.type == 1 ? std::pow(v, c.params[0])
                                   : (v >= c.params[4] ? std::pow(c.params[1] * v + c.params[2], c.params[0]) : c.params[3] * v);
      worst = std::max(worst, std::abs(l - decode[static_cast<std::size_t>(j)]));
    }
    if (worst < 2e-4) {
      cs.curve_type = c.type;
      cs.curve_parameters = c.params;
      cs.cicp = spectral::cicp_code_points(cs);
      return cs;
    }
  }
  cs.curve_table = std::move(decode);
  return cs;  // no cICP: H.273 codes no tabulated curve
}

void write_output_image(const fs::path& path, const XyzImage& image, const OutputOptions& opts,
                        const ImageMetadata& metadata, const std::string& input, OutputGroup* group) {
  const OutputFormat format = output_format_for(path, input);
  check_output_path(path, input);
  check_output_options(format, opts);

  // Pixels: linear XYZ / colour space for EXR, display-encoded and clamped to [0, 1] otherwise.
  std::vector<float> pixels;
  std::optional<PictureColourSpace> colour_space;
  if (needs_transform(format, opts)) {
    const DisplayTransform transform(transform_options(format, opts));
    pixels = to_display(image, transform);
    if (format != OutputFormat::Exr) colour_space = display_colour_space(transform, opts.display.display);
  } else {
    pixels = image.xyz;
    for (float& v : pixels)
      if (!std::isfinite(v)) v = 0.0f;
  }
  PictureSpec spec;
  spec.width = image.width;
  spec.height = image.height;
  spec.stored = PicturePixelType::Float;
  if (format != OutputFormat::Exr) {
    for (float& v : pixels) v = std::clamp(v, 0.0f, 1.0f);
    spec.stored = opts.bit_depth == 16 ? PicturePixelType::UInt16 : PicturePixelType::UInt8;
  }
  // R, G, B in every format: an XYZ EXR holds X, Y, Z in them with XYZ's chromaticities (below), the
  // convention of OpenEXR (ImfChromaticities.h, "CIE XYZ"), so every RGBA reader gets the colours
  // (channels named X, Y, Z were read as a grey image with chromaticities applying to nothing).
  spec.channel_names = {"R", "G", "B"};
  if (format == OutputFormat::Exr) {
    spec.attributes.emplace_back("compression", "zip");
    if (const auto chromaticities = exr_chromaticities(opts)) {
      spec.float_attributes.emplace_back("chromaticities", std::vector<float>(chromaticities->begin(), chromaticities->end()));
    }
  } else {
    // PNG, TIFF, JPEG: an ICC profile of the display's colour space, when its transform is a matrix
    // and a per-channel curve (display_colour_space).
    spec.colour_space = colour_space;
    // PNG: also the display's name (OpenImageIO writes the sRGB chunk for "sRGB"). Not for TIFF:
    // OpenImageIO 2.4's TIFF writer then leaves a file without its ImageLength field.
    if (format == OutputFormat::Png) spec.attributes.emplace_back("oiio:ColorSpace", opts.display.display);
    if (format == OutputFormat::Jpeg) spec.attributes.emplace_back("Compression", "jpeg:95");
  }
  if (format == OutputFormat::Tiff || format == OutputFormat::Jpeg) {
    // TIFF and JPEG keep no text keys of their own (OpenImageIO drops "prizma:…" there): the
    // provenance goes, as one JSON object of the same keys, into the image description (TIFF's
    // ImageDescription tag; JPEG's comment and Exif ImageDescription), which every reader shows and
    // OpenImageIO reads back as "ImageDescription". Software keeps its own field in both.
    nlohmann::json provenance = nlohmann::json::object();
    for (const auto& [key, value] : metadata) {
      if (key == "Software") spec.attributes.emplace_back(key, value);
      else provenance[key] = value;
    }
    spec.attributes.emplace_back("ImageDescription", provenance.dump());
  } else {
    for (const auto& [key, value] : metadata) spec.attributes.emplace_back(key, value);
  }

  write_atomically(path, [&](AtomicOutput& out) {
    write_picture(out, spec, PicturePixelType::Float, pixels.data());
  }, group);
}

}  // namespace prizma::spectral
