// libprizma_vdb.so: OpenVDB volumes through Debian's libopenvdb, behind the C interface of
// renderer/include/prizma/render/vdb_module.h. One float grid, densified over the bounding box of its
// active voxels for the tracer's lookups, with the majorant's per-block value ranges taken from the
// tree's leaf nodes and tiles, so that the empty space between them is never visited.
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <mutex>
#include <new>
#include <string>

#include "prizma/render/vdb_module.h"

struct PrizmaVdbGrid {
  openvdb::FloatGrid::Ptr grid;
  openvdb::CoordBBox box;  // active voxels' bounding box, index space
};

namespace {

// A failure with its status, thrown inside the module only (never across the C interface).
struct Failure {
  int status;
  std::string message;
};

void put_message(const std::string& text, char* message, std::size_t size) {
  if (message == nullptr || size == 0) return;
  std::snprintf(message, size, "%s", text.c_str());
}

// Runs `body`, mapping every exception to a status and one line of message.
template <class Body>
int guarded(char* message, std::size_t size, int failed_status, Body&& body) {
  try {
    body();
    return PRIZMA_VDB_OK;
  } catch (const Failure& f) {
    put_message(f.message, message, size);
    return f.status;
  } catch (const std::bad_alloc&) {
    put_message("out of memory", message, size);
    return PRIZMA_VDB_OUT_OF_MEMORY;
  } catch (const openvdb::Exception& e) {
    put_message(failed_status == PRIZMA_VDB_BAD_FILE ? std::string("not a readable OpenVDB file (") + e.what() + ")"
                                                    : std::string(e.what()),
                message, size);
    return failed_status;
  } catch (const std::exception& e) {
    put_message(e.what(), message, size);
    return PRIZMA_VDB_FAILED;
  } catch (...) {
    put_message("unknown error in the VDB module", message, size);
    return PRIZMA_VDB_FAILED;
  }
}

// Floor division for block indices of voxels that may lie one voxel outside the box.
int floor_div(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

std::string grid_names(openvdb::io::File& file) {
  std::string names;
  for (auto it = file.beginName(); it != file.endName(); ++it) names += (names.empty() ? "" : ", ") + it.gridName();
  return names.empty() ? std::string("none") : names;
}

// The grid's index → world map must be a scale and a translation (voxels aligned with the axes), as
// the renderer's volume is an axis-aligned box; returns the voxel size per axis.
std::array<double, 3> axis_aligned_voxel_size(const openvdb::FloatGrid& grid) {
  const openvdb::math::Transform& xf = grid.transform();
  if (!xf.isLinear())
    throw Failure{PRIZMA_VDB_BAD_GRID, "has a non-linear (frustum) transform; only axis-aligned voxels are supported"};
  const openvdb::math::Mat4d m = xf.baseMap()->getAffineMap()->getMat4();
  std::array<double, 3> size{};
  for (int r = 0; r < 3; ++r) {
    size[r] = std::abs(m(r, r));
    for (int c = 0; c < 3; ++c) {
      if (c != r && std::abs(m(r, c)) > 1e-9 * (std::abs(m(r, r)) + std::abs(m(c, c)))) {
        throw Failure{PRIZMA_VDB_BAD_GRID, "has a rotated or sheared transform; only axis-aligned voxels are supported"};
      }
    }
    if (!(size[r] > 0.0) || !std::isfinite(size[r]))
      throw Failure{PRIZMA_VDB_BAD_GRID, "has a degenerate voxel size " + std::to_string(m(r, r))};
  }
  return size;
}

int open_grid(const char* path, const char* grid_name, PrizmaVdbGrid** out, PrizmaVdbGridInfo* info, char* message,
              std::size_t size) {
  *out = nullptr;
  PrizmaVdbGrid* made = nullptr;
  const int rc = guarded(message, size, PRIZMA_VDB_BAD_FILE, [&] {
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
    // The grid, by name, as a float grid.
    openvdb::GridBase::Ptr base;
    openvdb::io::File file(path);
    file.open(false);  // no delayed loading: the file is read now, not behind our back later
    if (!file.hasGrid(grid_name)) {
      const std::string names = grid_names(file);
      file.close();
      throw Failure{PRIZMA_VDB_BAD_FILE, "no grid named \"" + std::string(grid_name) + "\" (grids in the file: " + names + ")"};
    }
    base = file.readGrid(grid_name);
    file.close();
    const openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
    if (!grid) throw Failure{PRIZMA_VDB_BAD_GRID, "is of type " + base->valueType() + ", not float"};
    if (grid->activeVoxelCount() == 0) throw Failure{PRIZMA_VDB_BAD_GRID, "has no active voxels (empty grid)"};
    const std::array<double, 3> voxel_size = axis_aligned_voxel_size(*grid);
    const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
    const openvdb::Coord dim = box.dim();
    for (int a = 0; a < 3; ++a) {
      info->dims[a] = dim[a];
      info->voxel_size[a] = voxel_size[a];
    }
    made = new PrizmaVdbGrid{grid, box};
  });
  if (rc == PRIZMA_VDB_OK) *out = made;
  return rc;
}

int copy_dense(const PrizmaVdbGrid* g, float* values, char* message, std::size_t size) {
  return guarded(message, size, PRIZMA_VDB_FAILED, [&] {
    // Dense over the active bounding box (index space), x fastest, through the library's copyToDense.
    openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(g->box, values);
    openvdb::tools::copyToDense(*g->grid, dense, /*serial=*/false);
  });
}

int block_ranges(const PrizmaVdbGrid* g, int kB, float* ranges, char* message, std::size_t size) {
  return guarded(message, size, PRIZMA_VDB_FAILED, [&] {
    if (kB < 1) throw Failure{PRIZMA_VDB_FAILED, "block size must be positive"};
    const openvdb::Coord dim = g->box.dim();
    const int dims[3] = {dim.x(), dim.y(), dim.z()};
    int nb[3];
    for (int a = 0; a < 3; ++a) nb[a] = (dims[a] + kB - 1) / kB;
    const std::size_t blocks = static_cast<std::size_t>(nb[0]) * nb[1] * nb[2];
    // The background (outside every node) widens every block's range.
    const float inf = std::numeric_limits<float>::infinity();
    const float bg = g->grid->background();
    for (std::size_t k = 0; k < blocks; ++k) {
      ranges[2 * k] = std::isfinite(bg) ? bg : inf;
      ranges[2 * k + 1] = std::isfinite(bg) ? bg : -inf;
    }
    // Each leaf voxel and each tile (active or not) widens the range of the blocks whose
    // interpolation stencil it meets: block c's points interpolate voxels c·B − 1 … c·B + B.
    const openvdb::Coord origin = g->box.min();
    for (auto it = g->grid->tree().cbeginValueAll(); it; ++it) {
      const float v = *it;
      if (!std::isfinite(v)) continue;
      openvdb::CoordBBox b;
      it.getBoundingBox(b);
      int lo[3], hi[3];
      bool inside = true;
      for (int a = 0; a < 3; ++a) {
        // The voxels of this value inside the dense box, relative to its origin (64-bit: tiles reach far).
        const long long i0 = std::max<long long>(0, static_cast<long long>(b.min()[a]) - origin[a]);
        const long long i1 = std::min<long long>(dims[a] - 1, static_cast<long long>(b.max()[a]) - origin[a]);
        if (i0 > i1) {
          inside = false;
          break;
        }
        lo[a] = std::max(0, floor_div(static_cast<int>(i0) - 1, kB));
        hi[a] = std::min(nb[a] - 1, floor_div(static_cast<int>(i1) + 1, kB));
      }
      if (!inside) continue;
      for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
          for (int x = lo[0]; x <= hi[0]; ++x) {
            float* r = ranges + 2 * ((static_cast<std::size_t>(z) * nb[1] + y) * nb[0] + x);
            r[0] = std::min(r[0], v);
            r[1] = std::max(r[1], v);
          }
    }
  });
}

void close_grid(PrizmaVdbGrid* g) { delete g; }

const PrizmaVdbModule kModule{PRIZMA_VDB_ABI_VERSION, open_grid, copy_dense, block_ranges, close_grid};

}  // namespace

extern "C" __attribute__((visibility("default"))) const PrizmaVdbModule* prizma_vdb_module_v1() { return &kModule; }
