// OpenVDB volumes (.vdb) through Debian's libopenvdb: one float grid, densified over the bounding box
// of its active voxels for the tracer's lookups, with the majorant's per-block value ranges taken
// from the tree's leaf nodes and tiles, so that the empty space between them is never visited.
#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <string>

#include "prizma/render/volume.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/input_file.h"
#include "volume_budget.h"

namespace prizma::render {

using spectral::InputError;

namespace {

// Floor division for block indices of voxels that may lie one voxel outside the box.
int floor_div(int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

std::string grid_names(openvdb::io::File& file) {
  std::string names;
  for (auto it = file.beginName(); it != file.endName(); ++it) names += (names.empty() ? "" : ", ") + it.gridName();
  return names.empty() ? std::string("none") : names;
}

// The grid's index → world map must be a scale and a translation (voxels aligned with the axes), as
// the renderer's volume is an axis-aligned box; returns the voxel size per axis.
std::array<double, 3> axis_aligned_voxel_size(const openvdb::FloatGrid& grid, const std::string& where) {
  const openvdb::math::Transform& xf = grid.transform();
  if (!xf.isLinear()) throw InputError(where, "has a non-linear (frustum) transform; only axis-aligned voxels are supported");
  const openvdb::math::Mat4d m = xf.baseMap()->getAffineMap()->getMat4();
  std::array<double, 3> size{};
  for (int r = 0; r < 3; ++r) {
    size[r] = std::abs(m(r, r));
    for (int c = 0; c < 3; ++c) {
      if (c != r && std::abs(m(r, c)) > 1e-9 * (std::abs(m(r, r)) + std::abs(m(c, c)))) {
        throw InputError(where, "has a rotated or sheared transform; only axis-aligned voxels are supported");
      }
    }
    if (!(size[r] > 0.0) || !std::isfinite(size[r])) {
      throw InputError(where, "has a degenerate voxel size " + std::to_string(m(r, r)));
    }
  }
  return size;
}

}  // namespace

Volume load_vdb_volume(const std::filesystem::path& path, const std::string& grid_name) {
  const std::string input = path.string();
  spectral::require_regular_file(path, "an OpenVDB file");
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });

  // The grid, by name, as a float grid.
  openvdb::GridBase::Ptr base;
  try {
    openvdb::io::File file(input);
    file.open(false);  // no delayed loading: the file is read now, not behind our back later
    if (!file.hasGrid(grid_name)) {
      const std::string names = grid_names(file);
      file.close();
      throw InputError(input, "no grid named \"" + grid_name + "\" (grids in the file: " + names + ")");
    }
    base = file.readGrid(grid_name);
    file.close();
  } catch (const openvdb::Exception& e) {
    throw InputError(input, std::string("not a readable OpenVDB file (") + e.what() + ")");
  }
  const std::string where = input + ": grid \"" + grid_name + "\"";
  const openvdb::FloatGrid::Ptr grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
  if (!grid) throw InputError(where, "is of type " + base->valueType() + ", not float");
  if (grid->activeVoxelCount() == 0) throw InputError(where, "has no active voxels (empty grid)");
  const std::array<double, 3> voxel_size = axis_aligned_voxel_size(*grid, where);

  // Dense over the active bounding box (index space), x fastest, through the library's copyToDense.
  const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
  const openvdb::Coord dim = box.dim();
  const std::array<int, 3> dims{dim.x(), dim.y(), dim.z()};
  const std::size_t count = detail::check_volume_fits(dims, 0, where);
  Volume vol;
  vol.dims = dims;
  vol.spacing = voxel_size;
  vol.source = input;
  vol.values.resize(count);
  openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box, vol.values.data());
  openvdb::tools::copyToDense(*grid, dense, /*serial=*/false);

  // Per-block value ranges from the tree's values: each leaf voxel, each tile (active or not) and the
  // background (outside every node) widens the range of the blocks whose interpolation stencil it
  // meets: block c's points interpolate voxels c·8 − 1 … c·8 + 8 (as MajorantGrid::build_trilinear).
  constexpr int kB = Volume::kBlockVoxels;
  std::array<int, 3> nb{};
  for (int a = 0; a < 3; ++a) nb[a] = (dims[a] + kB - 1) / kB;
  const float inf = std::numeric_limits<float>::infinity();
  const float bg = grid->background();
  const std::array<float, 2> start = std::isfinite(bg) ? std::array<float, 2>{bg, bg} : std::array<float, 2>{inf, -inf};
  vol.block_range.assign(static_cast<std::size_t>(nb[0]) * nb[1] * nb[2], start);
  const openvdb::Coord origin = box.min();
  for (auto it = grid->tree().cbeginValueAll(); it; ++it) {
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
          auto& r = vol.block_range[(static_cast<std::size_t>(z) * nb[1] + y) * nb[0] + x];
          r[0] = std::min(r[0], v);
          r[1] = std::max(r[1], v);
        }
  }
  return vol;
}

}  // namespace prizma::render
