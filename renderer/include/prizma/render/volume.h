#pragma once
// Volume: a scalar field on a regular grid with physical voxel spacing, as loaded from disk or made
// procedurally. Values keep their original units (raw intensities, Hounsfield, …) as float.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace prizma::render {

struct Volume {
  std::array<int, 3> dims{0, 0, 0};            // voxels along x, y, z
  std::array<double, 3> spacing{1.0, 1.0, 1.0};  // physical voxel size (any unit; only ratios matter)
  std::vector<float> values;                   // x fastest: values[(z·ny + y)·nx + x]
  std::string source;                          // file path or procedural name, for messages
  // Optional, from sparse sources (OpenVDB): the range [lo, hi] of the finite values that a point of
  // each block of kBlockVoxels³ voxels can interpolate between (the block's voxels and their
  // neighbours), blocks aligned with voxel 0, x fastest; built from the tree's leaves and tiles so
  // that empty space is never visited. Empty = the majorant grid reads the voxels. lo > hi = no value.
  static constexpr int kBlockVoxels = 8;
  std::vector<std::array<float, 2>> block_range;
  // Human-readable notes for the render's log (e.g. the NIfTI orientation applied); may be empty.
  std::string orientation;
  // What the file's library noticed in a file it still read ("cloud.vdb: OpenVDB: unsupported VDB file
  // format (…)"), one line each: the tools print them as warnings.
  std::vector<std::string> warnings;

  std::size_t voxel_count() const { return static_cast<std::size_t>(dims[0]) * dims[1] * dims[2]; }
  float at(int x, int y, int z) const {
    return values[(static_cast<std::size_t>(z) * dims[1] + y) * dims[0] + x];
  }
};

enum class VoxelType { U8, U16, I16, F32 };

struct RawVolumeSpec {
  std::filesystem::path path;
  std::array<int, 3> dims{0, 0, 0};  // 0,0,0 = parse from a name like chameleon_1024x1024x1080_uint16.raw
  VoxelType type = VoxelType::U8;
  bool type_given = false;           // false = parse from the name
  bool big_endian = false;
  std::array<double, 3> spacing{1.0, 1.0, 1.0};
};

// Raw files. Throws InputError naming the file when the size does not match dims × type, the name
// cannot be parsed, or the volume would not fit in memory (checked before allocation).
Volume load_raw_volume(const RawVolumeSpec& spec);
// NIfTI-1 .nii / .nii.gz through libnifti; spacing from pixdim. Throws InputError for corrupt,
// truncated or unsupported (complex, RGB) files. The voxels are reordered (axes permuted and
// flipped, no resampling) so that volume +x, +y, +z point to the patient's Right, Anterior and
// Superior (RAS+, the NIfTI world frame) by the sform (sform_code > 0) or else the qform
// (qform_code > 0); with neither the file order is kept. Volume::orientation says what was done.
Volume load_nifti_volume(const std::filesystem::path& path);
// OpenVDB .vdb: the float grid named `grid`, densified over its active voxels' bounding box, voxel
// size from the grid's linear transform, block_range from the tree's leaf nodes and tiles. Throws
// InputError (one line, naming the file) for a missing or unreadable file, a missing grid (the
// message lists the grids there), a grid that is not float, a non-linear or non-uniformly
// scaled transform, no active voxels, or a bounding box too large for memory.
Volume load_vdb_volume(const std::filesystem::path& path, const std::string& grid);
// Procedural volumes at resolution n³ over [−1, 1]³:
//   cube_sphere     VPT's sphere_in_cube: 0 outside, 100 in the cube max|x|<0.8, 255 in the sphere r<0.5
//   homogeneous_box 1 everywhere
//   metamer_pair    two spheres side by side (values 100 left, 200 right), 0 elsewhere
Volume make_procedural_volume(const std::string& name, int resolution);
std::vector<std::string> procedural_volume_names();

}  // namespace prizma::render
