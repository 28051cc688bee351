// Loading libprizma_imageio.so on first use, and the tool's side of its interface.
#include "prizma/spectral/image_io.h"

#include <dlfcn.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <system_error>
#include <vector>

#include "prizma/spectral/atomic_file.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/tool_main.h"

namespace prizma::spectral {

namespace {

namespace fs = std::filesystem;
namespace mod = image_io_module;

constexpr const char* kModuleFile = "libprizma_imageio.so";

fs::path executable_folder() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : exe.parent_path();
}

std::vector<fs::path> candidates() {
  std::vector<fs::path> out;
  if (const char* env = std::getenv("PRIZMA_IMAGE_IO_MODULE"); env != nullptr && *env != '\0') {
    out.emplace_back(env);
    return out;  // explicit: nothing else
  }
  const fs::path dir = executable_folder();
  if (!dir.empty()) {
    out.push_back(dir / kModuleFile);
    out.push_back(dir.parent_path() / "lib" / "prizma" / kModuleFile);
  }
  // This code inside a shared object that is not the executable: the Python module, installed as
  // <prefix>/lib/python3.X/site-packages/prizma/_prizma.so (or lib/python3/dist-packages), whose
  // image module is <prefix>/lib/prizma/ three folders up.
  static const char anchor = 0;
  Dl_info info{};
  if (::dladdr(&anchor, &info) != 0 && info.dli_fname != nullptr && *info.dli_fname != '\0') {
    std::error_code ec;
    const fs::path so = fs::absolute(fs::path(info.dli_fname), ec).parent_path();
    if (!ec && so != dir) {
      out.push_back(so / kModuleFile);
      out.push_back(so.parent_path().parent_path().parent_path() / "prizma" / kModuleFile);
    }
  }
#ifdef PRIZMA_IMAGE_IO_BUILD_PATH
  out.emplace_back(PRIZMA_IMAGE_IO_BUILD_PATH);
#endif
  return out;
}

bool address_space_limited() {
  rlimit lim{};
  return ::getrlimit(RLIMIT_AS, &lim) == 0 && lim.rlim_cur != RLIM_INFINITY;
}

const mod::Module* load_module() {
  const std::vector<fs::path> paths = candidates();
  fs::path chosen;
  for (const fs::path& p : paths) {
    std::error_code ec;
    if (fs::exists(p, ec)) {
      chosen = p;
      break;
    }
  }
  if (chosen.empty()) {
    std::string looked;
    for (const fs::path& p : paths) looked += (looked.empty() ? "" : ", ") + p.string();
    throw RuntimeError("cannot find the image module " + std::string(kModuleFile) +
                       " (needed for PNG, TIFF and transfer-function images; looked in: " + looked + ")");
  }
  // Near an address-space limit, OpenImageIO's dependencies fail inside their initialisers in
  // ways that cannot all be caught (log4cplus calls std::terminate; one limit, 485 MB, hung): the
  // ~450 MB its libraries map must be there before it is loaded.
  if (address_space_limited()) {
    rlimit lim{};
    ::getrlimit(RLIMIT_AS, &lim);
    long long used_kb = 0;
    if (std::FILE* f = std::fopen("/proc/self/status", "r")) {
      char line[256];
      while (std::fgets(line, sizeof line, f) != nullptr)
        if (std::sscanf(line, "VmSize: %lld kB", &used_kb) == 1) break;
      std::fclose(f);
    }
    constexpr long long kNeededMb = 512;
    const long long left_mb = static_cast<long long>(lim.rlim_cur / (1024 * 1024)) - used_kb / 1024;
    if (left_mb < kNeededMb) {
      throw RuntimeError("out of memory loading the image module " + chosen.string() + " (" +
                         std::to_string(left_mb) + " MB of address space left under the limit; it maps about " +
                         std::to_string(kNeededMb) + " MB)");
    }
  }
  void* handle = nullptr;
  {
    // OpenImageIO's dependencies start threads and allocate in their initialisers: a crash or an
    // exception there under a memory limit is reported as out of memory, as before main.
    const LoadGuard guard("loading the image module " + chosen.string());
    handle = ::dlopen(chosen.c_str(), RTLD_NOW | RTLD_LOCAL);
  }
  if (handle == nullptr) {
    const char* e = ::dlerror();
    const std::string why = e != nullptr ? e : "unknown error";
    if (message_says_out_of_memory(why) ||
        (address_space_limited() && why.find("failed to map segment") != std::string::npos)) {
      throw RuntimeError("out of memory loading the image module " + chosen.string() + " (" + why + ")");
    }
    throw RuntimeError("cannot load the image module " + chosen.string() + ": " + why);
  }
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

PictureColourSpace srgb_picture_colour_space() {
  PictureColourSpace cs;
  cs.name = "sRGB";
  cs.chromaticities = {0.64, 0.33, 0.30, 0.60, 0.15, 0.06, 0.3127, 0.3290};  // IEC 61966-2-1 table 1
  return cs;  // the default curve: type 4 with the standard's parameters
}

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
