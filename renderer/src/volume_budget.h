#pragma once
// Private to the volume loaders: the check that a volume fits in memory, done before allocating.
#include <array>
#include <cstddef>
#include <string>

namespace prizma::render::detail {

// Bytes a loaded volume of `dims` costs: the file's voxels (`file_bytes_per_voxel`), the float values
// and the medium built from them (material index + density). Throws InputError (input `input`)
// when a dimension is not positive, the computation overflows, or the total exceeds the physical
// memory of this machine. Returns the voxel count.
std::size_t check_volume_fits(const std::array<int, 3>& dims, std::size_t file_bytes_per_voxel,
                              const std::string& input);

// The physical memory of this machine in bytes (sysconf), or SIZE_MAX when unknown.
std::size_t physical_memory_bytes();

}  // namespace prizma::render::detail
