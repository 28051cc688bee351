// libprizma_imageio.so: the tools' only OpenImageIO code, loaded on first use (see
// libspectral/include/prizma/spectral/image_io.h for why and how it is found).
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <lcms2.h>

#include <array>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "prizma/spectral/image_io.h"

namespace {

using prizma::spectral::PictureColourSpace;
using prizma::spectral::PicturePixelType;
using prizma::spectral::PictureReader;
using prizma::spectral::PictureSpec;
namespace mod = prizma::spectral::image_io_module;

OIIO::TypeDesc type_of(PicturePixelType t) {
  switch (t) {
    case PicturePixelType::UInt8: return OIIO::TypeDesc::UINT8;
    case PicturePixelType::UInt16: return OIIO::TypeDesc::UINT16;
    case PicturePixelType::Float: return OIIO::TypeDesc::FLOAT;
  }
  return OIIO::TypeDesc::UINT8;
}

// An OpenImageIO IOProxy writing into the tool's ByteSink (an AtomicOutput): the image libraries
// are C, so nothing throws; a failure is recorded by the sink and the call returns a short count.
class SinkProxy final : public OIIO::Filesystem::IOProxy {
 public:
  SinkProxy(const std::string& name, mod::ByteSink& sink) : IOProxy(name, Write), m_sink(sink) {}
  const char* proxytype() const override { return "prizma-atomic"; }
  int64_t tell() override { return m_sink.tell(); }
  bool seek(int64_t offset) override { return m_sink.seek(offset); }
  size_t write(const void* buf, size_t size) override { return m_sink.write(buf, size) ? size : 0; }
  size_t pwrite(const void* buf, size_t size, int64_t offset) override {
    return m_sink.write_at(buf, size, offset) ? size : 0;
  }
  size_t read(void* buf, size_t size) override {
    const std::int64_t at = m_sink.tell();
    const std::size_t got = m_sink.read_at(buf, size, at);
    m_sink.seek(at + static_cast<std::int64_t>(got));
    return got;
  }
  size_t pread(void* buf, size_t size, int64_t offset) override { return m_sink.read_at(buf, size, offset); }
  size_t size() const override { return static_cast<size_t>(m_sink.size()); }

 private:
  mod::ByteSink& m_sink;
};

// Little CMS's error handler: its message into the std::string that is the context's user data.
void record_lcms_error(cmsContext ctx, cmsUInt32Number, const char* text) {
  if (auto* message = static_cast<std::string*>(cmsGetContextUserData(ctx))) *message = text != nullptr ? text : "";
}

// An RGB matrix/TRC ICC profile (v4) of `cs`, made by Little CMS: the primaries and white as given
// (stored adapted to the D50 connection space, with the adaptation in the chad tag, as ICC v4
// requires), one curve for all three channels, the name as the profile description. Empty with
// `reason` set when Little CMS refuses (e.g. primaries that do not span a space).
std::vector<unsigned char> icc_profile(const PictureColourSpace& cs, std::string& reason) {
  std::string lcms_error;
  cmsContext ctx = cmsCreateContext(nullptr, &lcms_error);
  if (ctx == nullptr) {
    reason = "cannot make the ICC profile (out of memory)";
    return {};
  }
  cmsSetLogErrorHandlerTHR(ctx, record_lcms_error);
  const auto& c = cs.chromaticities;
  const cmsCIExyY white{c[6], c[7], 1.0};
  const cmsCIExyYTRIPLE primaries{{c[0], c[1], 1.0}, {c[2], c[3], 1.0}, {c[4], c[5], 1.0}};
  cmsToneCurve* curve =
      cs.curve_table.empty()
          ? cmsBuildParametricToneCurve(ctx, cs.curve_type, cs.curve_parameters.data())
          : cmsBuildTabulatedToneCurveFloat(ctx, static_cast<cmsUInt32Number>(cs.curve_table.size()), cs.curve_table.data());
  std::vector<unsigned char> bytes;
  cmsHPROFILE profile = nullptr;
  cmsMLU* description = nullptr;
  if (curve != nullptr) {
    cmsToneCurve* curves[3] = {curve, curve, curve};
    profile = cmsCreateRGBProfileTHR(ctx, &white, &primaries, curves);
  }
  if (profile != nullptr) description = cmsMLUalloc(ctx, 1);
  cmsUInt32Number size = 0;
  if (description != nullptr && cmsMLUsetASCII(description, "en", "US", cs.name.c_str()) &&
      cmsWriteTag(profile, cmsSigProfileDescriptionTag, description) && cmsSaveProfileToMem(profile, nullptr, &size) &&
      size > 0) {
    bytes.resize(size);
    if (!cmsSaveProfileToMem(profile, bytes.data(), &size)) bytes.clear();
  }
  if (description != nullptr) cmsMLUfree(description);
  if (profile != nullptr) cmsCloseProfile(profile);
  if (curve != nullptr) cmsFreeToneCurve(curve);
  cmsDeleteContext(ctx);
  if (bytes.empty()) {
    reason = "cannot make the ICC profile of colour space \"" + cs.name + "\"" +
             (lcms_error.empty() ? std::string() : " (Little CMS: " + lcms_error + ")");
  }
  return bytes;
}

// The last error OpenImageIO holds (the reader's, else the global one), on one line; both are
// cleared, so that nothing is left for OpenImageIO to print at exit. A reader records one line per
// failed strip or scanline (a TIFF cut in half: one per missing strip), so the line keeps the first
// kShownLines and counts the rest.
std::string one_line_error(OIIO::ImageInput* in) {
  constexpr int kShownLines = 3;
  std::string e = in != nullptr ? in->geterror() : std::string();
  const std::string global = OIIO::geterror();
  if (e.empty()) e = global;
  std::string line;
  int lines = 0;
  std::size_t start = 0;
  while (start < e.size()) {
    std::size_t end = e.find_first_of("\r\n", start);
    if (end == std::string::npos) end = e.size();
    std::string part = e.substr(start, end - start);
    while (!part.empty() && part.back() == ' ') part.pop_back();
    if (!part.empty() && ++lines <= kShownLines) line += (line.empty() ? "" : " ") + part;
    start = end + 1;
  }
  if (lines > kShownLines) line += " (and " + std::to_string(lines - kShownLines) + " more messages)";
  return line.empty() ? "unknown error" : line;
}

// CRC-32 of PNG chunks (ISO 3309, polynomial 0xEDB88320, as the PNG specification's annex D computes it).
std::uint32_t png_crc(const unsigned char* data, std::size_t n, std::uint32_t crc = 0xFFFFFFFFu) {
  for (std::size_t i = 0; i < n; ++i) {
    crc ^= data[i];
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
  }
  return crc;
}

// Inserts a cICP chunk (PNG 3rd edition, §11.3.2.6: H.273 code points, before PLTE and IDAT) right
// after the IHDR chunk of the PNG in `sink` (libpng 1.6.39 and OpenImageIO 2.4 write none). False
// when the bytes are not a PNG starting with IHDR or the sink fails.
bool insert_cicp_chunk(mod::ByteSink& sink, const std::array<std::uint8_t, 4>& cicp) {
  constexpr std::int64_t kAfterIhdr = 8 + 8 + 13 + 4;  // signature, IHDR's length and type, data, CRC
  const std::int64_t size = sink.size();
  if (size < kAfterIhdr) return false;
  std::vector<unsigned char> rest(static_cast<std::size_t>(size - kAfterIhdr));
  unsigned char head[16];
  if (sink.read_at(head, sizeof head, 0) != sizeof head || head[1] != 'P' || head[2] != 'N' || head[3] != 'G' ||
      std::string(reinterpret_cast<const char*>(head + 12), 4) != "IHDR" ||
      sink.read_at(rest.data(), rest.size(), kAfterIhdr) != rest.size()) {
    return false;
  }
  unsigned char chunk[4 + 4 + 4 + 4] = {0, 0, 0, 4, 'c', 'I', 'C', 'P', cicp[0], cicp[1], cicp[2], cicp[3]};
  const std::uint32_t crc = png_crc(chunk + 4, 8) ^ 0xFFFFFFFFu;
  for (int k = 0; k < 4; ++k) chunk[12 + k] = static_cast<unsigned char>(crc >> (24 - 8 * k));
  return sink.write_at(chunk, sizeof chunk, kAfterIhdr) &&
         sink.write_at(rest.data(), rest.size(), kAfterIhdr + static_cast<std::int64_t>(sizeof chunk));
}

// Formats whose OpenImageIO writer embeds an "ICCProfile" attribute in the file. Others (OpenEXR,
// HDR, …) have no place for one: OpenEXR's writer would print "Don't know what to do with …
// ICCProfile" and drop it.
bool embeds_icc_profile(const OIIO::ImageOutput& image) {
  const std::string format = image.format_name();
  return format == "png" || format == "tiff" || format == "jpeg";
}

// OpenImageIO's debug messages ("OIIO DEBUG: …") go to stderr in Debian's build, in successful runs
// too; they are for OpenImageIO's developers. Off, unless the user asked for them with
// OPENIMAGEIO_DEBUG (OpenImageIO's own variable).
void quiet_library_debug_messages() {
  static const bool done = [] {
    const char* asked = std::getenv("OPENIMAGEIO_DEBUG");
    if (asked == nullptr || *asked == '\0') OIIO::attribute("debug", 0);
    return true;
  }();
  (void)done;
}

class OiioReader final : public PictureReader {
 public:
  explicit OiioReader(std::unique_ptr<OIIO::ImageInput> in) : m_in(std::move(in)), m_spec(m_in->spec()) {}
  ~OiioReader() override { m_in->close(); }
  OiioReader(const OiioReader&) = delete;
  OiioReader& operator=(const OiioReader&) = delete;
  int width() const override { return m_spec.width; }
  int height() const override { return m_spec.height; }
  int channels() const override { return m_spec.nchannels; }
  std::size_t channel_bytes() const override { return m_spec.format.size(); }
  // A reader that hits the end of a truncated file may still return true, with the rows it could
  // not decode left as zeros (TIFF, JPEG: "Premature end of JPEG file"): any error it recorded
  // fails the read.
  bool read_float(float* pixels, std::string& error) override {
    const bool read = m_in->read_image(0, 0, 0, m_spec.nchannels, OIIO::TypeDesc::FLOAT, pixels);
    if (read && !m_in->has_error()) return true;
    error = one_line_error(m_in.get());
    return false;
  }

 private:
  std::unique_ptr<OIIO::ImageInput> m_in;
  OIIO::ImageSpec m_spec;
};

class OiioModule final : public mod::Module {
 public:
  int abi_version() const override { return mod::kAbiVersion; }

  bool can_write(const std::string& filename, std::string& reason) const override {
    if (OIIO::ImageOutput::create(filename)) return true;
    reason = OIIO::geterror();
    return false;
  }

  mod::WriteStatus write(mod::ByteSink& sink, const std::string& filename, const PictureSpec& ps,
                         PicturePixelType given, const void* pixels, std::string& reason) const override {
    OIIO::ImageSpec spec(ps.width, ps.height, ps.channels, type_of(ps.stored));
    if (!ps.channel_names.empty()) spec.channelnames = ps.channel_names;
    for (const auto& [key, value] : ps.attributes) spec.attribute(key, value);
    for (const auto& [key, values] : ps.float_attributes) {
      spec.attribute(key, OIIO::TypeDesc(OIIO::TypeDesc::FLOAT, static_cast<int>(values.size())), values.data());
    }
    SinkProxy proxy(filename, sink);
    std::unique_ptr<OIIO::ImageOutput> image = OIIO::ImageOutput::create(filename, &proxy);
    if (!image) {
      reason = OIIO::geterror();
      return mod::WriteStatus::UnknownFormat;
    }
    const std::string format = image->format_name();
    if (ps.colour_space && embeds_icc_profile(*image)) {
      const std::vector<unsigned char> icc = icc_profile(*ps.colour_space, reason);
      if (icc.empty()) return mod::WriteStatus::Failed;
      spec.attribute("ICCProfile", OIIO::TypeDesc(OIIO::TypeDesc::UINT8, static_cast<int>(icc.size())), icc.data());
      // Exif's ColorSpace: 1 is sRGB (H.273 primaries 1 and transfer 13), 0xFFFF "uncalibrated"
      // (another space: the profile says which).
      const auto& cicp = ps.colour_space->cicp;
      const bool srgb = cicp && (*cicp)[0] == 1 && (*cicp)[1] == 13;
      // Not for TIFF: OpenImageIO 2.4's TIFF writer then leaves out the ImageLength field (as it does
      // for oiio:ColorSpace), and the file cannot be read.
      if (format == "jpeg") spec.attribute("Exif:ColorSpace", srgb ? 1 : 0xFFFF);
    }
    if (!image->supports("ioproxy")) return mod::WriteStatus::NoIoProxy;
    const auto fail = [&](const char* what) {
      reason = image->geterror();
      if (reason.empty()) reason = what;
      return mod::WriteStatus::Failed;
    };
    if (!image->set_ioproxy(&proxy)) return fail("cannot set the output");
    if (!image->open(filename, spec)) return fail("cannot open for writing");
    if (!image->write_image(type_of(given), pixels)) {
      image->close();
      return fail("cannot write the image");
    }
    if (!image->close()) return fail("cannot finish the image");
    if (format == "png" && ps.colour_space && ps.colour_space->cicp && !insert_cicp_chunk(sink, *ps.colour_space->cicp)) {
      reason = "cannot add the cICP chunk";
      return mod::WriteStatus::Failed;
    }
    return mod::WriteStatus::Ok;
  }

  std::unique_ptr<PictureReader> open(const std::string& filename, std::string& error) const override {
    auto in = OIIO::ImageInput::open(filename);
    if (!in) {
      error = one_line_error(nullptr);
      return nullptr;
    }
    return std::make_unique<OiioReader>(std::move(in));
  }
};

}  // namespace

extern "C" __attribute__((visibility("default"))) const mod::Module* prizma_image_io_module_v1() {
  quiet_library_debug_messages();
  static const OiioModule module;
  return &module;
}
