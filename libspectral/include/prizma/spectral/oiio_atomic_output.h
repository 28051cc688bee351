#pragma once
// OpenImageIO writers into write_atomically's checked temporary. Header-only: include it only from
// targets that link OpenImageIO (the renderer's preview, prizma-relight's images).
//
// Why: OpenImageIO's PNG and TIFF writers do not report a short write (a full disk or a file-size
// limit gave exit 0 and a truncated PNG). Every byte goes through an IOProxy over AtomicOutput, which
// records the first failure; write_atomically then refuses the file whatever the writer reported.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <memory>
#include <string>

#include "prizma/spectral/atomic_file.h"
#include "prizma/spectral/error.h"

namespace prizma::spectral {

// An OpenImageIO IOProxy writing into an AtomicOutput. Never throws (the image libraries are C);
// a failure is recorded in the AtomicOutput and the call returns a short count.
class OiioAtomicProxy final : public OIIO::Filesystem::IOProxy {
 public:
  explicit OiioAtomicProxy(AtomicOutput& out) : IOProxy(out.temporary().string(), Write), m_out(out) {}
  const char* proxytype() const override { return "prizma-atomic"; }
  int64_t tell() override { return m_out.tell(); }
  bool seek(int64_t offset) override { return m_out.seek(offset); }
  size_t write(const void* buf, size_t size) override { return m_out.write(buf, size) ? size : 0; }
  size_t pwrite(const void* buf, size_t size, int64_t offset) override {
    return m_out.write_at(buf, size, offset) ? size : 0;
  }
  size_t read(void* buf, size_t size) override {
    const std::int64_t at = m_out.tell();
    const std::size_t got = m_out.read_at(buf, size, at);
    m_out.seek(at + static_cast<std::int64_t>(got));
    return got;
  }
  size_t pread(void* buf, size_t size, int64_t offset) override { return m_out.read_at(buf, size, offset); }
  size_t size() const override { return static_cast<size_t>(m_out.size()); }

 private:
  AtomicOutput& m_out;
};

// Writes one image with OpenImageIO, the format chosen by the destination's extension, into `out`.
// `pixels` are `type` values, channels interleaved, rows top to bottom. Throws RuntimeError naming
// the destination with OpenImageIO's message (or the write's own failure, which takes precedence).
inline void write_oiio_image(AtomicOutput& out, const OIIO::ImageSpec& spec, OIIO::TypeDesc type,
                             const void* pixels) {
  const std::string name = out.destination().string();
  OiioAtomicProxy proxy(out);
  std::unique_ptr<OIIO::ImageOutput> image = OIIO::ImageOutput::create(name, &proxy);
  if (!image) throw RuntimeError(name + ": cannot write this format: " + OIIO::geterror());
  if (!image->supports("ioproxy")) throw RuntimeError(name + ": this format cannot be written safely (no ioproxy)");
  const auto fail = [&](const std::string& what) {
    std::string reason = image->geterror();
    if (reason.empty()) reason = what;
    if (out.failed()) reason = out.error();
    out.fail(reason);
    throw RuntimeError(name + ": " + reason);
  };
  if (!image->set_ioproxy(&proxy)) fail("cannot set the output");
  if (!image->open(name, spec)) fail("cannot open for writing");
  if (!image->write_image(type, pixels)) {
    image->close();
    fail("cannot write the image");
  }
  if (!image->close()) fail("cannot finish the image");
}

}  // namespace prizma::spectral
