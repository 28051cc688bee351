// Loading libprizma_imageio.so on first use, and the tool's side of its interface.
#include "prizma/spectral/image_io.h"

#include <dlfcn.h>

#include <filesystem>
#include <mutex>

#include "prizma/spectral/atomic_file.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/module_loader.h"

namespace prizma::spectral {

namespace {

namespace mod = image_io_module;

const mod::Module* load_module() {
  ModuleSpec spec;
  spec.file = "libprizma_imageio.so";
  spec.env_var = "PRIZMA_IMAGE_IO_MODULE";
  spec.name = "image module";
  spec.needed_for = "needed for PNG, TIFF and transfer-function images";
#ifdef PRIZMA_IMAGE_IO_BUILD_PATH
  spec.build_path = PRIZMA_IMAGE_IO_BUILD_PATH;
#endif
  // Near an address-space limit, OpenImageIO's dependencies fail inside their initialisers in
  // ways that cannot all be caught (log4cplus calls std::terminate; one limit, 485 MB, hung): the
  // ~450 MB its libraries map must be there before it is loaded.
  spec.address_space_needed_mb = 512;
  std::filesystem::path chosen;
  void* handle = open_module(spec, chosen);
  using Entry = const mod::Module* (*)();
  auto entry = reinterpret_cast<Entry>(::dlsym(handle, mod::kEntryPoint));
  const mod::Module* m = entry != nullptr ? entry() : nullptr;
  if (m == nullptr || m->abi_version() != mod::kAbiVersion) {
    throw RuntimeError("cannot load the image module " + chosen.string() +
                       ": not a Prizma image module of this version (rebuild it with the tools)");
  }
  // Never dlclose'd: OpenImageIO keeps threads and caches until exit.
  return m;
}

std::mutex g_mutex;
const mod::Module* g_module = nullptr;

const mod::Module& module() {
  const std::lock_guard<std::mutex> lock(g_mutex);
  if (g_module == nullptr) g_module = load_module();
  return *g_module;
}

class AtomicSink final : public mod::ByteSink {
 public:
  explicit AtomicSink(AtomicOutput& out) : m_out(out) {}
  std::int64_t tell() override { return m_out.tell(); }
  bool seek(std::int64_t offset) override { return m_out.seek(offset); }
  bool write(const void* data, std::size_t n) override { return m_out.write(data, n); }
  bool write_at(const void* data, std::size_t n, std::int64_t offset) override {
    return m_out.write_at(data, n, offset);
  }
  std::size_t read_at(void* data, std::size_t n, std::int64_t offset) override {
    return m_out.read_at(data, n, offset);
  }
  std::int64_t size() override { return m_out.size(); }

 private:
  AtomicOutput& m_out;
};

}  // namespace

bool image_io_module_loaded() {
  const std::lock_guard<std::mutex> lock(g_mutex);
  return g_module != nullptr;
}

void write_picture(AtomicOutput& out, const PictureSpec& spec, PicturePixelType given, const void* pixels) {
  const std::string name = out.destination().string();
  const mod::Module& m = module();
  AtomicSink sink(out);
  std::string reason;
  switch (m.write(sink, name, spec, given, pixels, reason)) {
    case mod::WriteStatus::Ok: return;
    case mod::WriteStatus::UnknownFormat: throw RuntimeError(name + ": cannot write this format: " + reason);
    case mod::WriteStatus::NoIoProxy: throw RuntimeError(name + ": this format cannot be written safely (no ioproxy)");
    case mod::WriteStatus::Failed: break;
  }
  if (out.failed()) reason = out.error();
  out.fail(reason);
  throw RuntimeError(name + ": " + reason);
}

bool can_write_picture(const std::string& path, std::string& reason) { return module().can_write(path, reason); }

std::unique_ptr<PictureReader> open_picture(const std::string& path, std::string& error) {
  return module().open(path, error);
}

}  // namespace prizma::spectral
