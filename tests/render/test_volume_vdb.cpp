// OpenVDB volumes (issue 13 part 6): grids written here through libopenvdb (a sphere of density with
// an offset index box and a translated transform), read back densified over the active box; the
// per-block value ranges built from the tree against the dense voxels; the majorant grid against the
// one built from the dense voxels; renders of the .vdb against a dense raw file of the same values
// (3 standard errors, fixed seeds); and the one-line errors.
#include <gtest/gtest.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>
#include <openvdb/tools/LevelSetUtil.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <typeinfo>
#include <vector>

#include "prizma/render/majorant_grid.h"
#include "prizma/render/render.h"
#include "prizma/render/transfer_function.h"
#include "prizma/render/volume.h"
#include "prizma/spectral/error.h"
#include "render_test_scenes.h"
#include "test_scene_util.h"

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PRIZMA_TEST_ASAN 1
#endif
#endif

namespace prizma::render {
namespace {

using spectral::InputError;
using testing::pixel_average;
using testing::ScratchDir;

constexpr double kSe = 3.0;  // tolerance in standard errors (fixed seeds)

// The sphere: index box [kOrigin, kOrigin + kN), centre in its middle, value 1 − r/R inside r < R.
constexpr int kN = 24;
const openvdb::Coord kOrigin(-37, 5, 100);
constexpr double kRadius = 11.0;
double sphere_value(int x, int y, int z) {  // x, y, z relative to kOrigin
  const double c = 0.5 * (kN - 1);
  const double r = std::sqrt((x - c) * (x - c) + (y - c) * (y - c) + (z - c) * (z - c));
  return r < kRadius ? 1.0 - r / kRadius : -1.0;  // −1: not active
}

void init_vdb() {
  static bool done = false;
  if (!done) openvdb::initialize();
  done = true;
}

void write_grids(const std::filesystem::path& path, const openvdb::GridPtrVec& grids) {
  openvdb::io::File file(path.string());
  file.write(grids);
  file.close();
}

openvdb::FloatGrid::Ptr sphere_grid(double voxel_size) {
  init_vdb();
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName("density");
  auto xf = openvdb::math::Transform::createLinearTransform(voxel_size);
  xf->postTranslate(openvdb::Vec3d(3.0, -4.0, 5.0));
  grid->setTransform(xf);
  auto acc = grid->getAccessor();
  for (int z = 0; z < kN; ++z)
    for (int y = 0; y < kN; ++y)
      for (int x = 0; x < kN; ++x) {
        const double v = sphere_value(x, y, z);
        if (v >= 0.0) acc.setValue(kOrigin.offsetBy(x, y, z), static_cast<float>(v));
      }
  return grid;
}

// The same values as a dense float32 raw file over the sphere's active box (written directly from
// sphere_value, not from the loader), and that box's first index and size.
void write_raw(const std::filesystem::path& path, openvdb::CoordBBox box) {
  std::ofstream out(path, std::ios::binary);
  for (int z = box.min().z(); z <= box.max().z(); ++z)
    for (int y = box.min().y(); y <= box.max().y(); ++y)
      for (int x = box.min().x(); x <= box.max().x(); ++x) {
        const double v = sphere_value(x - kOrigin.x(), y - kOrigin.y(), z - kOrigin.z());
        const float f = v >= 0.0 ? static_cast<float>(v) : 0.0f;
        out.write(reinterpret_cast<const char*>(&f), sizeof f);
      }
}

TEST(VdbVolume, ReadsTheActiveBoxWithVoxelSize) {
  ScratchDir dir;
  auto grid = sphere_grid(0.02);
  write_grids(dir / "s.vdb", {grid});
  const Volume vol = load_vdb_volume(dir / "s.vdb", "density");
  const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
  EXPECT_EQ(vol.dims, (std::array<int, 3>{box.dim().x(), box.dim().y(), box.dim().z()}));
  EXPECT_LT(vol.dims[0], kN);  // the corners of the written cube are inactive: the box is tighter
  for (int a = 0; a < 3; ++a) EXPECT_DOUBLE_EQ(vol.spacing[a], 0.02);
  auto acc = grid->getConstAccessor();
  std::size_t i = 0;
  for (int z = 0; z < vol.dims[2]; ++z)
    for (int y = 0; y < vol.dims[1]; ++y)
      for (int x = 0; x < vol.dims[0]; ++x, ++i)
        ASSERT_EQ(vol.values[i], acc.getValue(box.min().offsetBy(x, y, z))) << x << " " << y << " " << z;
}

TEST(VdbVolume, NonUniformAxisAlignedScaleGivesSpacing) {
  ScratchDir dir;
  auto grid = sphere_grid(1.0);
  openvdb::math::Mat4d m = openvdb::math::Mat4d::identity();
  m.setToScale(openvdb::Vec3d(0.5, 1.0, 2.0));
  grid->setTransform(openvdb::math::Transform::createLinearTransform(m));
  write_grids(dir / "s.vdb", {grid});
  const Volume vol = load_vdb_volume(dir / "s.vdb", "density");
  EXPECT_DOUBLE_EQ(vol.spacing[0], 0.5);
  EXPECT_DOUBLE_EQ(vol.spacing[1], 1.0);
  EXPECT_DOUBLE_EQ(vol.spacing[2], 2.0);
}

TEST(VdbVolume, BlockRangesHoldEveryStencilValue) {
  // Block c's points interpolate voxels c·8 − 1 … c·8 + 8 (clamped): the range built from the tree
  // must contain each of those voxels' values.
  ScratchDir dir;
  write_grids(dir / "s.vdb", {sphere_grid(0.02)});
  const Volume vol = load_vdb_volume(dir / "s.vdb", "density");
  constexpr int kB = Volume::kBlockVoxels;
  std::array<int, 3> nb{};
  for (int a = 0; a < 3; ++a) nb[a] = (vol.dims[a] + kB - 1) / kB;
  ASSERT_EQ(vol.block_range.size(), static_cast<std::size_t>(nb[0]) * nb[1] * nb[2]);
  for (int bz = 0; bz < nb[2]; ++bz)
    for (int by = 0; by < nb[1]; ++by)
      for (int bx = 0; bx < nb[0]; ++bx) {
        const auto r = vol.block_range[(static_cast<std::size_t>(bz) * nb[1] + by) * nb[0] + bx];
        const int b[3] = {bx, by, bz};
        int lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
          lo[a] = std::max(0, b[a] * kB - 1);
          hi[a] = std::min(vol.dims[a] - 1, b[a] * kB + kB);
        }
        for (int z = lo[2]; z <= hi[2]; ++z)
          for (int y = lo[1]; y <= hi[1]; ++y)
            for (int x = lo[0]; x <= hi[0]; ++x) {
              const float v = vol.at(x, y, z);
              ASSERT_LE(r[0], v) << bx << " " << by << " " << bz;
              ASSERT_GE(r[1], v) << bx << " " << by << " " << bz;
            }
      }
}

TransferFunction sphere_materials() {
  TransferFunction tf;
  tf.materials = {testing::grey_material(0.8, 12.0)};
  MaterialRule r;
  r.material = 0;
  r.value_lo = 0.05;
  r.value_hi = std::numeric_limits<double>::infinity();
  r.density.values = {0.05, 1.0};
  r.density.densities = {0.0, 1.0};
  tf.rules = {r};
  return tf;
}

TEST(VdbVolume, MajorantFromTheTreeBoundsTheDenseOne) {
  // The tree-built majorant is a bound wherever the dense build (which reads every voxel of every
  // cell's stencil and is exact for the value range) is, and it is 0 where no active value is near.
  ScratchDir dir;
  write_grids(dir / "s.vdb", {sphere_grid(0.02)});
  const Volume vol = load_vdb_volume(dir / "s.vdb", "density");
  const TransferFunction tf = sphere_materials();
  const std::vector<float> sigma_t_max{12.0f};
  for (Interpolation ip : {Interpolation::Trilinear, Interpolation::Nearest}) {
    const Medium sparse = build_medium(vol, tf, "test", ip);
    ASSERT_FALSE(sparse.block_range.empty());
    Medium dense = sparse;
    dense.block_range.clear();
    for (int cells : {MajorantGrid::kCellVoxels, 16, 0}) {
      const MajorantGrid gs(sparse, sigma_t_max, cells), gd(dense, sigma_t_max, cells);
      ASSERT_EQ(gs.cells(), gd.cells());
      int positive = 0;
      for (int z = 0; z < gs.cells()[2]; ++z)
        for (int y = 0; y < gs.cells()[1]; ++y)
          for (int x = 0; x < gs.cells()[0]; ++x) {
            EXPECT_GE(gs.majorant(x, y, z), gd.majorant(x, y, z)) << x << " " << y << " " << z << " cells " << cells;
            positive += gs.majorant(x, y, z) > 0.0f;
          }
      EXPECT_GT(positive, 0);
      EXPECT_LE(gs.max_majorant(), std::nextafter(12.0f, 1e30f) * 1.0001f);
    }
  }
}

TEST(VdbVolume, RendersLikeADenseRawVolumeOfTheSameValues) {
  ScratchDir dir;
  auto grid = sphere_grid(0.02);
  write_grids(dir / "s.vdb", {grid});
  const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
  write_raw(dir / "s.raw", box);
  const std::string tail =
      R"(, "materials": [{"range": [0.05, 1e9], "albedo": 0.8, "extinction": 12, "density": [[0.05, 0], [1, 1]]}],
  "camera": {"type": "orthographic", "position": [0, 0, 2], "look_at": [0, 0, 0], "ortho_height": 1.1,
             "width": 12, "height": 12},
  "lights": [{"name": "sun", "direction": [0.3, 0.8, 0.5]}, {"name": "env", "direction": [0, 0, 0]}],
  "bins": "linear:400:700:2", "samples": 48, "seed": 5, "normalisation": {"min": 0, "max": 1}})";
  for (const std::string ip : {"trilinear", "nearest"}) {
    SCOPED_TRACE(ip);
    const std::string raw_dims = "[" + std::to_string(box.dim().x()) + ", " + std::to_string(box.dim().y()) + ", " +
                                 std::to_string(box.dim().z()) + "]";
    dir.write("vdb.json", R"({"volume": {"type": "vdb", "path": "s.vdb", "grid": "density", "interpolation": ")" + ip +
                              "\"}" + tail);
    dir.write("raw.json", R"({"volume": {"type": "raw", "path": "s.raw", "voxel_type": "float32", "dims": )" +
                              raw_dims + R"(, "spacing": [0.02, 0.02, 0.02], "interpolation": ")" + ip + "\"}" + tail);
    Scene sv = load_scene(dir / "vdb.json"), sr = load_scene(dir / "raw.json");
    EXPECT_EQ(sv.medium.dims, sr.medium.dims);
    for (Scene* s : {&sv, &sr}) s->settings.write_variance = true;
    for (std::uint64_t seed : {5, 6}) {
      sv.settings.seed = sr.settings.seed = seed;
      const auto iv = render(sv), ir = render(sr);
      for (int light = 0; light < 2; ++light) {
        const auto a = pixel_average(iv, light), b = pixel_average(ir, light);
        for (std::size_t k = 0; k < a.mean.size(); ++k) {
          const double se = std::sqrt(a.se[k] * a.se[k] + b.se[k] * b.se[k]);
          EXPECT_NEAR(a.mean[k], b.mean[k], kSe * se) << "seed " << seed << " light " << light << " bin " << k;
          EXPECT_GT(se, 0.0);
        }
      }
    }
  }
}

void expect_input_error(const std::filesystem::path& path, const std::string& grid, const std::string& words) {
  try {
    load_vdb_volume(path, grid);
    ADD_FAILURE() << "no error for " << path << " grid " << grid;
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(words), std::string::npos) << what;
    EXPECT_NE(what.find(path.string()), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(VdbVolume, BadFilesAndGridsAreOneLineInputErrors) {
  ScratchDir dir;
  init_vdb();
  expect_input_error(dir / "missing.vdb", "density", "");
  const auto junk = dir.write("junk.vdb", "this is not a vdb file at all, just some bytes");
  expect_input_error(junk, "density", "not a readable OpenVDB file");

  auto ints = openvdb::Int32Grid::create(0);
  ints->setName("labels");
  ints->tree().setValue(openvdb::Coord(1, 2, 3), 7);
  auto empty = openvdb::FloatGrid::create(0.0f);
  empty->setName("empty");
  auto rotated = sphere_grid(0.1);
  rotated->setName("rotated");
  rotated->transform().preRotate(0.3, openvdb::math::X_AXIS);
  write_grids(dir / "g.vdb", {ints, empty, rotated});
  expect_input_error(dir / "g.vdb", "density", "no grid named \"density\" (grids in the file: empty, labels, rotated)");
  expect_input_error(dir / "g.vdb", "labels", "grid \"labels\": is of type int32, not float");
  expect_input_error(dir / "g.vdb", "empty", "grid \"empty\": has no active voxels (empty grid)");
  expect_input_error(dir / "g.vdb", "rotated", "rotated or sheared transform");
  write_grids(dir / "none.vdb", {});
  expect_input_error(dir / "none.vdb", "density", "no grid named \"density\" (the file holds no grids)");
}

// issue 21: a level set (signed distances, negative inside) was read as density, a hollow shell of
// its narrow band. It is refused, saying what to do; what it says to do (sdfToFogVolume) then reads.
TEST(VdbVolume, LevelSetIsRefusedAndItsFogVolumeReads) {
  ScratchDir dir;
  init_vdb();
  auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(0.3f, openvdb::Vec3f(0.0f), 0.02f, 3.0f);
  sphere->setName("density");
  write_grids(dir / "level_set.vdb", {sphere});
  expect_input_error(dir / "level_set.vdb", "density",
                     "grid \"density\": is a level set (signed distances to a surface, not densities); convert it "
                     "to a fog volume first");
  openvdb::tools::sdfToFogVolume(*sphere);
  write_grids(dir / "fog.vdb", {sphere});
  const Volume fog = load_vdb_volume(dir / "fog.vdb", "density");
  EXPECT_GT(fog.voxel_count(), 27000u);  // the ball of radius 15 voxels
  EXPECT_EQ(*std::max_element(fog.values.begin(), fog.values.end()), 1.0f);
}

std::string cloud_vdb_bytes() {
  std::ifstream in(std::filesystem::path(PRIZMA_TEST_DATA_DIR) / "scenes" / "cloud.vdb", std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// A copy of a real file (data/scenes/cloud.vdb, written by prizma-make-cloud-vdb) cut short anywhere
// is an InputError that says so, the same every run: OpenVDB 10 itself went on with a size it had
// not read at the file's end (an uninitialised variable), so a file cut in its leaf data was "out of
// memory" (exit 1) before issue 21, then "Expected to decompress 1024 bytes", or, 1 run in ~30,
// an allocation of terabytes AddressSanitizer aborts on. Every length up to past the grid's
// descriptor, then every sixteenth.
TEST(VdbVolume, FilesCutShortAreInputErrorsSayingSo) {
  ScratchDir dir;
  const std::string good = cloud_vdb_bytes();
  ASSERT_EQ(good.size(), 42125u);
  std::vector<std::size_t> lengths;
  for (std::size_t n = 0; n < 400; ++n) lengths.push_back(n);
  for (std::size_t k = 1; k < 16; ++k) lengths.push_back(good.size() * k / 16);
  lengths.push_back(good.size() - 1);
  int in_header = 0, in_grid = 0;
  for (const std::size_t n : lengths) {
    const auto path = dir.write("cut.vdb", good.substr(0, n));
    try {
      load_vdb_volume(path, "density");
      ADD_FAILURE() << "cut at " << n << ": read";
    } catch (const InputError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(path.string()), std::string::npos) << n << ": " << m;
      const std::string end = "the file ends at byte " + std::to_string(n) + ", inside its header or a grid's descriptor";
      const std::string grid = "grid \"density\" ends at byte 42125, the file at byte " + std::to_string(n) + ")";
      if (n == 0) {
        EXPECT_NE(m.find("not a readable OpenVDB file (the file is empty)"), std::string::npos) << m;
      } else if (m.find("not a readable OpenVDB file (cut short: " + end + ")") != std::string::npos) {
        ++in_header;
      } else {
        EXPECT_NE(m.find("not a readable OpenVDB file (cut short: " + grid), std::string::npos) << n << ": " << m;
        ++in_grid;
      }
    } catch (const std::exception& e) {
      ADD_FAILURE() << "cut at " << n << ": " << typeid(e).name() << ": " << e.what();
    }
  }
  // The header and the grid's descriptor take the first ~200 bytes; the grid itself the rest.
  EXPECT_GT(in_header, 100);
  EXPECT_GT(in_grid, 16);
}

// The grid's descriptor holds its start and end positions (8 bytes, little-endian, 42125 in cloud.vdb): one
// before its start is refused as corrupt, one past the file's end as cut short, naming the grid.
TEST(VdbVolume, GridPositionsOutsideTheFileAreRefused) {
  ScratchDir dir;
  const std::string good = cloud_vdb_bytes();
  const std::int64_t end = 42125;
  const std::string end_bytes(reinterpret_cast<const char*>(&end), sizeof end);
  const std::size_t at = good.find(end_bytes);
  ASSERT_LT(at, 400u);  // in the descriptor, before the grid's data
  const auto with_end = [&](std::int64_t value) {
    std::string bytes = good;
    bytes.replace(at, sizeof value, std::string(reinterpret_cast<const char*>(&value), sizeof value));
    return dir.write("moved.vdb", bytes);
  };
  std::int64_t start = 0;  // the grid's start, two positions before its end (start, blocks, end)
  std::memcpy(&start, good.data() + at - 2 * sizeof start, sizeof start);
  ASSERT_GT(start, 1);
  expect_input_error(with_end(1), "density",
                     "not a readable OpenVDB file (corrupt: grid \"density\" at bytes " + std::to_string(start) + " to 1)");
  expect_input_error(with_end(99999), "density",
                     "not a readable OpenVDB file (cut short: grid \"density\" ends at byte 99999, the file at byte 42125)");
}

// issue 21: one byte changed in the leaf data of a real file asked for terabytes: "out of memory"
// (std::bad_alloc: exit 1). Now the file is an InputError naming it, or (a change OpenVDB cannot
// see) it reads; never another exception.
TEST(VdbVolume, DamagedFilesAreInputErrorsNotOutOfMemory) {
#if defined(__SANITIZE_ADDRESS__) || defined(PRIZMA_TEST_ASAN)
  // AddressSanitizer's allocator aborts on the damaged sizes (allocation-size-too-big) before
  // OpenVDB can throw, and the module's address-space bound is off there (vdb_module.cpp).
  GTEST_SKIP() << "not under AddressSanitizer";
#endif
  ScratchDir dir;
  const std::string good = cloud_vdb_bytes();
  ASSERT_EQ(good.size(), 42125u);
  int refused = 0, asked_too_much = 0;
  auto load = [&](const std::string& bytes, const std::string& what) {
    const auto path = dir.write("damaged.vdb", bytes);
    try {
      load_vdb_volume(path, "density");
    } catch (const InputError& e) {
      ++refused;
      const std::string m = e.what();
      EXPECT_NE(m.find(path.string()), std::string::npos) << what << ": " << m;
      asked_too_much += m.find("a size in it asks for more memory than any valid file of") != std::string::npos;
    } catch (const std::exception& e) {
      ADD_FAILURE() << what << ": " << typeid(e).name() << ": " << e.what();
    }
  };
  for (std::size_t at = 700; at < 1500; at += 3) {
    std::string bytes = good;
    bytes[at] = static_cast<char>(bytes[at] ^ 0x5a);
    load(bytes, "byte " + std::to_string(at));
  }
  EXPECT_GE(refused, 100);
  EXPECT_GE(asked_too_much, 20);  // std::bad_alloc before
}

// issue 21: a grid 1.5·10⁹ voxels from the origin (one changed byte of cloud.vdb put it there) crashed
// the dense copy: OpenVDB's parallel copyToDense splits the box at (min + max) / 2 in 32 bits. It reads
// exactly as the same grid near the origin.
TEST(VdbVolume, GridFarFromTheOriginReadsLikeNearIt) {
  ScratchDir dir;
  const openvdb::FloatGrid::Ptr near = sphere_grid(0.05);
  auto far = openvdb::FloatGrid::create(0.0f);
  far->setName("density");
  far->setTransform(near->transform().copy());
  const openvdb::Coord shift(0, 1509949440, -1200000000);
  auto acc = far->getAccessor();
  for (auto it = near->cbeginValueOn(); it; ++it) acc.setValue(it.getCoord() + shift, *it);
  write_grids(dir / "near.vdb", {near});
  write_grids(dir / "far.vdb", {far});
  const Volume a = load_vdb_volume(dir / "near.vdb", "density");
  const Volume b = load_vdb_volume(dir / "far.vdb", "density");
  EXPECT_EQ(a.dims, b.dims);
  EXPECT_EQ(a.values, b.values);
  EXPECT_EQ(a.block_range, b.block_range);
}

TEST(VdbVolume, SceneFieldsAreChecked) {
  ScratchDir dir;
  write_grids(dir / "s.vdb", {sphere_grid(0.02)});
  const std::string tail = R"(, "materials": [{"albedo": 0.8, "extinction": 1}], "lights": [{"name": "env", "direction": [0, 0, 0]}]})";
  dir.write("a.json", R"({"volume": {"type": "vdb", "path": "s.vdb", "grid": "smoke"})" + tail);
  EXPECT_THROW(load_scene(dir / "a.json"), InputError);
  dir.write("b.json", R"({"volume": {"type": "vdb", "path": "s.vdb", "grid": 3})" + tail);
  try {
    load_scene(dir / "b.json");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("volume.grid: must be a string"), std::string::npos) << e.what();
  }
  dir.write("c.json", R"({"volume": {"type": "vdb", "path": "s.vdb"})" + tail);  // grid defaults to density
  EXPECT_EQ(load_scene(dir / "c.json").medium.dims[0], load_vdb_volume(dir / "s.vdb", "density").dims[0]);
}

}  // namespace
}  // namespace prizma::render
