// Loading libprizma_imageio.so on first use, and the tool's side of its interface.
#include "prizma/spectral/image_io.h"

#include <dlfcn.h>

#include <cmath>
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

std::optional<std::array<std::uint8_t, 4>> cicp_code_points(const PictureColourSpace& cs) {
  // ITU-T H.273 (2016) table 2, colour primaries: xy of red, green, blue and white.
  struct Primaries {
    std::uint8_t code;
    std::array<double, 8> xy;
  };
  static constexpr Primaries kPrimaries[] = {
      {1, {0.640, 0.330, 0.300, 0.600, 0.150, 0.060, 0.3127, 0.3290}},    // BT.709, sRGB
      {9, {0.708, 0.292, 0.170, 0.797, 0.131, 0.046, 0.3127, 0.3290}},    // BT.2020, BT.2100
      {12, {0.680, 0.320, 0.265, 0.690, 0.150, 0.060, 0.3127, 0.3290}}};  // SMPTE EG 432-1 (P3-D65)
  std::optional<std::uint8_t> primaries;
  for (const Primaries& p : kPrimaries) {
    bool close = true;
    for (std::size_t i = 0; i < 8; ++i) close = close && std::abs(cs.chromaticities[i] - p.xy[i]) <= 0.002;
    if (close) primaries = p.code;
  }
  // Table 3, transfer characteristics, for the curves display_colour_space writes exactly.
  std::optional<std::uint8_t> transfer;
  if (cs.curve_table.empty()) {
    const auto& g = cs.curve_parameters;
    if (cs.curve_type == 4 && std::abs(g[0] - 2.4) < 1e-9 && std::abs(g[4] - 0.04045) < 1e-9) transfer = 13;  // sRGB
    if (cs.curve_type == 1 && std::abs(g[0] - 2.2) < 1e-9) transfer = 4;  // "assumed display gamma 2.2"
    if (cs.curve_type == 1 && std::abs(g[0] - 2.4) < 1e-9) transfer = 1;  // BT.709 / BT.2020 with BT.1886
  }
  if (!primaries || !transfer) return std::nullopt;
  return std::array<std::uint8_t, 4>{*primaries, *transfer, 0, 1};
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
