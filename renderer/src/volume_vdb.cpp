// OpenVDB volumes (.vdb) through the VDB module libprizma_vdb.so (vdb/vdb_module.cpp, the C interface
// of prizma/render/vdb_module.h), loaded the first time a "vdb" volume is read, so a render of a
// raw, NIfTI or procedural volume never maps OpenVDB and its libraries (start-up, docs/results.md).
#include <dlfcn.h>

#include <algorithm>
#include <array>
#include <memory>
#include <mutex>
#include <new>
#include <string>
#include <string_view>
#include <vector>

#include "prizma/render/vdb_module.h"
#include "prizma/render/volume.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/input_file.h"
#include "prizma/spectral/module_loader.h"
#include "volume_budget.h"

namespace prizma::render {

using spectral::InputError;
using spectral::RuntimeError;

namespace {

const PrizmaVdbModule* load_module() {
  spectral::ModuleSpec spec;
  spec.file = "libprizma_vdb.so";
  spec.env_var = "PRIZMA_VDB_MODULE";
  spec.name = "VDB module";
  spec.needed_for = "needed for OpenVDB volumes";
#ifdef PRIZMA_VDB_BUILD_PATH
  spec.build_path = PRIZMA_VDB_BUILD_PATH;
#endif
  // Near an address-space limit OpenVDB's log4cplus gives up starting its thread inside its
  // initialiser (caught by the load guard) or, once in a while, hangs: its libraries map about
  // 90 MB, so the module is loaded only with room to spare.
  spec.address_space_needed_mb = 200;
  std::filesystem::path chosen;
  void* handle = spectral::open_module(spec, chosen);
  auto entry = reinterpret_cast<PrizmaVdbEntry>(::dlsym(handle, PRIZMA_VDB_ENTRY_POINT));
  const PrizmaVdbModule* m = entry != nullptr ? entry() : nullptr;
  if (m == nullptr || m->abi_version != PRIZMA_VDB_ABI_VERSION) {
    throw RuntimeError("cannot load the VDB module " + chosen.string() +
                       ": not a Prizma VDB module of this version (rebuild it with the tools)");
  }
  return m;  // never dlclose'd: OpenVDB's libraries keep their state until exit
}

const PrizmaVdbModule& vdb_module() {
  static std::mutex mutex;
  static const PrizmaVdbModule* module = nullptr;
  const std::lock_guard<std::mutex> lock(mutex);
  if (module == nullptr) module = load_module();
  return *module;
}

// A failed call: input errors name the file or the grid, the rest are run-time failures.
[[noreturn]] void fail(int status, const std::string& input, const std::string& where, const char* message) {
  switch (status) {
    case PRIZMA_VDB_BAD_FILE: throw InputError(input, message);
    case PRIZMA_VDB_BAD_GRID: throw InputError(where, message);
    case PRIZMA_VDB_OUT_OF_MEMORY: throw std::bad_alloc();
    default: throw RuntimeError(input + ": " + message);
  }
}

}  // namespace

Volume load_vdb_volume(const std::filesystem::path& path, const std::string& grid_name) {
  const std::string input = path.string();
  spectral::require_regular_file(path, "an OpenVDB file");
  const PrizmaVdbModule& m = vdb_module();
  const std::string where = input + ": grid \"" + grid_name + "\"";
  char message[1024] = "";

  PrizmaVdbGrid* raw = nullptr;
  PrizmaVdbGridInfo info{};
  if (const int rc = m.open_grid(input.c_str(), grid_name.c_str(), &raw, &info, message, sizeof message); rc != PRIZMA_VDB_OK)
    fail(rc, input, where, message);
  const auto close = [&m](PrizmaVdbGrid* g) { m.close_grid(g); };
  const std::unique_ptr<PrizmaVdbGrid, decltype(close)> grid(raw, close);
  std::vector<std::string> warnings;
  for (std::string_view rest = info.warnings; !rest.empty();) {
    const std::size_t end = std::min(rest.find('\n'), rest.size());
    warnings.push_back(input + ": OpenVDB: " + std::string(rest.substr(0, end)));
    rest.remove_prefix(std::min(end + 1, rest.size()));
  }

  // Dense over the active bounding box, x fastest; checked to fit before it is allocated.
  const std::array<int, 3> dims{info.dims[0], info.dims[1], info.dims[2]};
  const std::size_t count = detail::check_volume_fits(dims, 0, where);
  Volume vol;
  vol.dims = dims;
  vol.spacing = {info.voxel_size[0], info.voxel_size[1], info.voxel_size[2]};
  vol.source = input;
  vol.warnings = std::move(warnings);
  vol.values.resize(count);
  if (const int rc = m.copy_dense(grid.get(), vol.values.data(), message, sizeof message); rc != PRIZMA_VDB_OK)
    fail(rc, input, where, message);

  // Per-block value ranges from the tree's leaves, tiles and background (vdb_module.h).
  constexpr int kB = Volume::kBlockVoxels;
  std::size_t blocks = 1;
  for (int a = 0; a < 3; ++a) blocks *= static_cast<std::size_t>((dims[a] + kB - 1) / kB);
  std::vector<float> ranges(2 * blocks);
  if (const int rc = m.block_ranges(grid.get(), kB, ranges.data(), message, sizeof message); rc != PRIZMA_VDB_OK)
    fail(rc, input, where, message);
  vol.block_range.resize(blocks);
  for (std::size_t k = 0; k < blocks; ++k) vol.block_range[k] = {ranges[2 * k], ranges[2 * k + 1]};
  return vol;
}

}  // namespace prizma::render
