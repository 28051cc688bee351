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
// truncated or unsupported (complex, RGB) files.
Volume load_nifti_volume(const std::filesystem::path& path);
// Procedural volumes at resolution n³ over [−1, 1]³:
//   cube_sphere     VPT's sphere_in_cube: 0 outside, 100 in the cube max|x|<0.8, 255 in the sphere r<0.5
//   homogeneous_box 1 everywhere
//   metamer_pair    two spheres side by side (values 100 left, 200 right), 0 elsewhere
Volume make_procedural_volume(const std::string& name, int resolution);
std::vector<std::string> procedural_volume_names();

}  // namespace prizma::render
