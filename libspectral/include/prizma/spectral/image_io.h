#pragma once
// Pictures (PNG, TIFF, EXR images that are not spectral files) and transfer-function images,
// through OpenImageIO — which is not linked into the tools. Debian's OpenImageIO pulls in about 260
// shared libraries (OpenVDB, log4cplus, ffmpeg, …) that cost a tool ~0.25 s and ~100 MB before main;
// a spectral render or relight that reads and writes only spectral EXRs (OpenEXR, linked) needs
// none of them. The OpenImageIO code lives in the module libprizma_imageio.so, loaded (dlopen) the
// first time one of the functions below is called. It is looked for as every module is
// (module_loader.h): $PRIZMA_IMAGE_IO_MODULE, next to the executable (or to the Python module's
// _prizma.so), <prefix>/lib/prizma/ of the installed tree (installed_prefix.h), the build tree's path.
// A module that cannot be loaded is a RuntimeError ("cannot load the image module <path>: <why>";
// "out of memory loading the image module …" when the address space ran out), exit 1.
#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace prizma::spectral {

class AtomicOutput;

enum class PicturePixelType { UInt8, UInt16, Float };

// The colour space a display-encoded picture (PNG, TIFF, JPEG) is encoded in, written into it as an
// ICC profile (an RGB matrix/TRC profile made by Little CMS in the image module). The transfer
// function maps an encoded value V in [0, 1] to linear light L: ICC parametric curve `curve_type`
// (1: L = V^g; 4: L = (aV + b)^g for V ≥ d, L = cV below — the sRGB form) with `curve_parameters`
// {g, a, b, c, d}, or, when `curve_table` is not empty, L sampled at V = i / (n − 1).
struct PictureColourSpace {
  std::string name;                        // the profile's description, e.g. "Display P3"
  std::array<double, 8> chromaticities{};  // CIE 1931 xy of red, green, blue and white
  int curve_type = 4;
  std::array<double, 5> curve_parameters{2.4, 1.0 / 1.055, 0.055 / 1.055, 1.0 / 12.92, 0.04045};
  std::vector<float> curve_table;
  // ITU-T H.273 code points {colour primaries, transfer characteristics, matrix coefficients, full
  // range}, written into a PNG as its cICP chunk (PNG 3rd edition), which readers that know it take
  // before the ICC profile; unset when H.273 has no code for the space (cicp_code_points).
  std::optional<std::array<std::uint8_t, 4>> cicp;
};

// The H.273 code points of a colour space, when its primaries and white are within 0.002 in xy of a
// coded set (1 BT.709 / sRGB, 9 BT.2020, 12 P3-D65: SMPTE EG 432-1) and its curve is one H.273
// codes: the sRGB piecewise curve (13), a 2.2 power (4), a 2.4 power (1: BT.709 / BT.2020, whose
// reference display is BT.1886, a 2.4 power with black at 0; ITU-T H-series Supplement 19). Matrix
// 0 (RGB), full range 1. Nothing for a table curve or other primaries.
std::optional<std::array<std::uint8_t, 4>> cicp_code_points(const PictureColourSpace& cs);

struct PictureSpec {
  int width = 0;
  int height = 0;
  int channels = 3;
  PicturePixelType stored = PicturePixelType::UInt8;           // type in the file
  std::vector<std::string> channel_names;                       // empty: OpenImageIO's default (R, G, B, …)
  std::vector<std::pair<std::string, std::string>> attributes;  // string metadata, e.g. {"compression", "zip"}
  std::vector<std::pair<std::string, std::vector<float>>> float_attributes;  // e.g. {"chromaticities", 8 floats}
  // PNG, TIFF, JPEG: embedded as an ICC profile (other formats have no place for one), and in a PNG
  // its cICP chunk; a JPEG also gets the Exif ColorSpace tag: 1 (sRGB) for cICP primaries 1 with
  // transfer 13, else 0xFFFF (Uncalibrated: "not sRGB, see the profile", Exif 2.32 §4.6.5).
  std::optional<PictureColourSpace> colour_space;
};

// Writes one picture into `out` (write_atomically's checked temporary), the format chosen by
// out.destination()'s extension. `pixels` are `given` values, channels interleaved, rows top to
// bottom. Every byte goes through `out`, so a short write fails the file whatever the writer says.
// Throws RuntimeError "<destination>: <reason>" (the write's own failure takes precedence).
void write_picture(AtomicOutput& out, const PictureSpec& spec, PicturePixelType given, const void* pixels);

// True when OpenImageIO can write the format of `path` (by its extension); otherwise false with
// OpenImageIO's reason in `reason`.
bool can_write_picture(const std::string& path, std::string& reason);

// A picture opened for reading.
class PictureReader {
 public:
  virtual ~PictureReader() = default;
  virtual int width() const = 0;
  virtual int height() const = 0;
  virtual int channels() const = 0;
  virtual std::size_t channel_bytes() const = 0;  // bytes per channel value in the file
  // Reads the whole first subimage as floats (8-bit values become value/255), channels
  // interleaved, into width·height·channels floats. False with the reader's error, on one line.
  virtual bool read_float(float* pixels, std::string& error) = 0;
};

// Opens `path`; nullptr with OpenImageIO's error (one line) when it cannot be read.
std::unique_ptr<PictureReader> open_picture(const std::string& path, std::string& error);

// Whether the module has been loaded in this process (diagnostics and tests).
bool image_io_module_loaded();

namespace image_io_module {

// What the module exports: extern "C" const Module* prizma_image_io_module_v1(). Compiled with
// the same compiler and library as the tools (it is built with them), so C++ types cross.
// 2: PictureSpec::float_attributes; 3: PictureSpec::colour_space; 4: PictureColourSpace::cicp
constexpr int kAbiVersion = 4;
constexpr const char* kEntryPoint = "prizma_image_io_module_v1";

// The bytes of the file being written (an AtomicOutput, adapted by the tool's side). Never throws.
class ByteSink {
 public:
  virtual std::int64_t tell() = 0;
  virtual bool seek(std::int64_t offset) = 0;
  virtual bool write(const void* data, std::size_t n) = 0;
  virtual bool write_at(const void* data, std::size_t n, std::int64_t offset) = 0;
  virtual std::size_t read_at(void* data, std::size_t n, std::int64_t offset) = 0;
  virtual std::int64_t size() = 0;

 protected:
  ~ByteSink() = default;
};

enum class WriteStatus { Ok, UnknownFormat, NoIoProxy, Failed };

class Module {
 public:
  virtual int abi_version() const = 0;
  virtual bool can_write(const std::string& filename, std::string& reason) const = 0;
  // Failed: `reason` is the writer's message (or Little CMS's, when the ICC profile of
  // spec.colour_space cannot be made), or `what` failed when it gave none; UnknownFormat:
  // OpenImageIO's message.
  virtual WriteStatus write(ByteSink& sink, const std::string& filename, const PictureSpec& spec,
                            PicturePixelType given, const void* pixels, std::string& reason) const = 0;
  virtual std::unique_ptr<PictureReader> open(const std::string& filename, std::string& error) const = 0;

 protected:
  ~Module() = default;
};

}  // namespace image_io_module

}  // namespace prizma::spectral
