// Raw volume files: headerless voxels, x fastest, of a type and size given by the scene or by the
// file name (chameleon_1024x1024x1080_uint16.raw).
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <bit>
#include <cstring>
#include <fstream>
#include <limits>
#include <regex>
#include <sstream>

#include "prizma/render/volume.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/input_file.h"
#include "volume_budget.h"

namespace prizma::render {

using spectral::InputError;

namespace detail {

std::size_t physical_memory_bytes() {
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long page_size = sysconf(_SC_PAGESIZE);
  if (pages <= 0 || page_size <= 0) return std::numeric_limits<std::size_t>::max();
  std::size_t total = 0;
  if (__builtin_mul_overflow(static_cast<std::size_t>(pages), static_cast<std::size_t>(page_size), &total)) {
    return std::numeric_limits<std::size_t>::max();
  }
  return total;
}

std::size_t check_volume_fits(const std::array<int, 3>& dims, std::size_t file_bytes_per_voxel,
                              const std::string& input) {
  for (int a = 0; a < 3; ++a) {
    if (dims[a] <= 0) {
      throw InputError(input, "dimensions must be positive (got " + std::to_string(dims[0]) + "x" +
                                  std::to_string(dims[1]) + "x" + std::to_string(dims[2]) + ")");
    }
  }
  // Per voxel: the file's bytes, a float value, a uint16 material and a float density.
  const std::size_t bytes_per_voxel = file_bytes_per_voxel + sizeof(float) + sizeof(std::uint16_t) + sizeof(float);
  std::size_t count = 1;
  std::size_t bytes = 0;
  bool overflow = false;
  for (int a = 0; a < 3; ++a) overflow |= __builtin_mul_overflow(count, static_cast<std::size_t>(dims[a]), &count);
  overflow |= __builtin_mul_overflow(count, bytes_per_voxel, &bytes);
  const std::size_t memory = physical_memory_bytes();
  if (overflow || bytes > memory) {
    std::ostringstream reason;
    reason << "volume " << dims[0] << "x" << dims[1] << "x" << dims[2] << " is too large for memory (needs ";
    if (overflow) {
      reason << "more than 2^64 bytes";
    } else {
      reason << bytes / (1024.0 * 1024.0 * 1024.0) << " GiB";
    }
    reason << ", this machine has " << memory / (1024.0 * 1024.0 * 1024.0) << " GiB)";
    throw InputError(input, reason.str());
  }
  return count;
}

}  // namespace detail

namespace {

std::size_t type_size(VoxelType t) {
  switch (t) {
    case VoxelType::U8: return 1;
    case VoxelType::U16: return 2;
    case VoxelType::I16: return 2;
    case VoxelType::F32: return 4;
  }
  return 1;
}

bool parse_type_name(const std::string& name, VoxelType& type) {
  if (name == "uint8" || name == "u8") type = VoxelType::U8;
  else if (name == "uint16" || name == "u16") type = VoxelType::U16;
  else if (name == "int16" || name == "i16") type = VoxelType::I16;
  else if (name == "float32" || name == "f32" || name == "float") type = VoxelType::F32;
  else return false;
  return true;
}

template <typename T>
T load_element(const unsigned char* p, bool swap) {
  unsigned char b[sizeof(T)];
  std::memcpy(b, p, sizeof(T));
  if (swap) std::reverse(b, b + sizeof(T));
  T v;
  std::memcpy(&v, b, sizeof(T));
  return v;
}

}  // namespace

// long on purpose: name parsing, size checks before any allocation and the chunked read, in the order a file is trusted.
Volume load_raw_volume(const RawVolumeSpec& spec) {
  const std::string input = spec.path.string();
  spectral::require_regular_file(spec.path, "a raw volume file");
  std::array<int, 3> dims = spec.dims;
  VoxelType type = spec.type;

  // Dimensions and type from the name when not given.
  const bool dims_given = dims != std::array<int, 3>{0, 0, 0};
  if (!dims_given || !spec.type_given) {
    static const std::regex kPattern(R"((\d+)x(\d+)x(\d+)_(uint8|uint16|int16|float32|float|u8|u16|i16|f32)(?:\.|$))",
                                     std::regex::icase);
    const std::string name = spec.path.filename().string();
    std::smatch m;
    if (!std::regex_search(name, m, kPattern)) {
      throw InputError(input, "cannot parse dimensions and voxel type from the file name (expected e.g. "
                              "name_256x256x128_uint16.raw with uint8, uint16, int16 or float32); give them "
                              "explicitly");
    }
    if (!dims_given) {
      for (int a = 0; a < 3; ++a) {
        const std::string digits = m[a + 1].str();
        if (digits.size() > 9) throw InputError(input, "dimension " + digits + " in the file name is too large");
        dims[a] = std::stoi(digits);
      }
    }
    if (!spec.type_given) {
      std::string t = m[4].str();
      std::transform(t.begin(), t.end(), t.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
      parse_type_name(t, type);
    }
  }
  for (int a = 0; a < 3; ++a) {
    if (!(spec.spacing[a] > 0.0) || !std::isfinite(spec.spacing[a])) {
      throw InputError(input, "spacing must be positive and finite (got " + std::to_string(spec.spacing[a]) + ")");
    }
  }

  // Size checks before any allocation.
  const std::size_t tsize = type_size(type);
  const std::size_t count = detail::check_volume_fits(dims, tsize, input);
  std::error_code ec;
  const auto file_size = std::filesystem::file_size(spec.path, ec);
  if (ec) throw InputError(input, "cannot read file: " + ec.message());
  const std::size_t expected = count * tsize;
  if (file_size != expected) {
    throw InputError(input, "file size " + std::to_string(file_size) + " bytes does not match " +
                                std::to_string(dims[0]) + "x" + std::to_string(dims[1]) + "x" +
                                std::to_string(dims[2]) + " voxels of " + std::to_string(tsize) +
                                " byte(s) = " + std::to_string(expected) + " bytes");
  }

  std::ifstream in(spec.path, std::ios::binary);
  if (!in) throw InputError(input, "cannot open file");
  Volume vol;
  vol.dims = dims;
  vol.spacing = spec.spacing;
  vol.source = input;
  vol.values.resize(count);
  const bool swap = spec.big_endian != (std::endian::native == std::endian::big);

  // Read in chunks so the file bytes never need a second full-size buffer.
  constexpr std::size_t kChunkVoxels = std::size_t{1} << 20;
  std::vector<unsigned char> buf(std::min(count, kChunkVoxels) * tsize);
  for (std::size_t first = 0; first < count; first += kChunkVoxels) {
    const std::size_t n = std::min(kChunkVoxels, count - first);
    in.read(reinterpret_cast<char*>(buf.data()), static_cast<std::streamsize>(n * tsize));
    if (static_cast<std::size_t>(in.gcount()) != n * tsize) {
      throw InputError(input, "file is truncated (read " + std::to_string(first * tsize + in.gcount()) +
                                  " of " + std::to_string(expected) + " bytes)");
    }
    float* out = vol.values.data() + first;
    const unsigned char* p = buf.data();
    switch (type) {
      case VoxelType::U8:
        for (std::size_t i = 0; i < n; ++i) out[i] = p[i];
        break;
      case VoxelType::U16:
        for (std::size_t i = 0; i < n; ++i) out[i] = load_element<std::uint16_t>(p + 2 * i, swap);
        break;
      case VoxelType::I16:
        for (std::size_t i = 0; i < n; ++i) out[i] = load_element<std::int16_t>(p + 2 * i, swap);
        break;
      case VoxelType::F32:
        for (std::size_t i = 0; i < n; ++i) out[i] = load_element<float>(p + 4 * i, swap);
        break;
    }
  }
  return vol;
}

}  // namespace prizma::render
