// libprizma_imageio.so: the tools' only OpenImageIO code, loaded on first use (see
// libspectral/include/prizma/spectral/image_io.h for why and how it is found).
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <memory>
#include <string>

#include "prizma/spectral/image_io.h"

namespace {

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

// The last error OpenImageIO holds (the reader's, else the global one), on one line; both are
// cleared, so that nothing is left for OpenImageIO to print at exit.
std::string one_line_error(OIIO::ImageInput* in) {
  std::string e = in != nullptr ? in->geterror() : std::string();
  const std::string global = OIIO::geterror();
  if (e.empty()) e = global;
  for (char& c : e) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  while (!e.empty() && e.back() == ' ') e.pop_back();
  return e.empty() ? "unknown error" : e;
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
  bool read_float(float* pixels, std::string& error) override {
    if (m_in->read_image(0, 0, 0, m_spec.nchannels, OIIO::TypeDesc::FLOAT, pixels)) return true;
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
  static const OiioModule module;
  return &module;
}
