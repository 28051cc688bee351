// libFuzzer target: the volume loaders' header handling — raw file names and size checks
// (load_raw_volume) and NIfTI-1 headers (load_nifti_volume on .nii and .nii.gz files).
// Input: byte 0 picks the mode, the rest is the payload.
//   0  raw, dims and type parsed from the name: payload = "<name>\n<file bytes>" (name filtered to
//      letters, digits, '_', '-', '.')
//   1  raw, dims and type given: payload = 3 × int32 dims, type byte, endian byte, file bytes
//   2  .nii with the payload as its bytes
//   3  .nii.gz with the payload gzip-compressed (reaches the NIfTI parser through zlib)
//   4  .nii.gz with the payload as its raw bytes (a corrupt or truncated gzip stream)
// InputError is the expected answer to a bad file; any other exception, a crash, undefined behaviour
// or a volume that breaks the Volume invariants is a bug. Inputs are capped at 64 KiB.
#include <zlib.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include "fuzz/fuzz_support.h"
#include "prizma/render/volume.h"

namespace {

constexpr std::size_t kMaxInputBytes = 64 * 1024;

void check_volume(const prizma::render::Volume& v) {
  for (int a = 0; a < 3; ++a) {
    PRIZMA_FUZZ_CHECK(v.dims[a] > 0, "dims[%d] = %d", a, v.dims[a]);
    PRIZMA_FUZZ_CHECK(std::isfinite(v.spacing[a]) && v.spacing[a] > 0.0, "spacing[%d] = %g", a, v.spacing[a]);
  }
  PRIZMA_FUZZ_CHECK(v.values.size() == v.voxel_count(), "%zu values for %dx%dx%d voxels", v.values.size(),
                    v.dims[0], v.dims[1], v.dims[2]);
}

std::string filtered_name(std::string_view name) {
  std::string out;
  for (char c : name.substr(0, 120)) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                    c == '-' || c == '.';
    if (ok) out += c;
  }
  if (out.empty() || out == "." || out == "..") out = "volume.raw";
  return out;
}

void write_gzip(const std::filesystem::path& path, std::string_view bytes) {
  gzFile gz = gzopen(path.c_str(), "wb");
  if (gz == nullptr) std::abort();
  if (!bytes.empty() && gzwrite(gz, bytes.data(), static_cast<unsigned>(bytes.size())) != static_cast<int>(bytes.size())) {
    std::abort();
  }
  if (gzclose(gz) != Z_OK) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace prizma::render;
  if (size < 1 || size > kMaxInputBytes) return 0;
  static const prizma::fuzz::ScratchDir dir("volume_headers");
  const int mode = data[0] % 5;
  const std::string_view payload(reinterpret_cast<const char*>(data) + 1, size - 1);

  switch (mode) {
    case 0: {
      const std::size_t newline = payload.find('\n');
      if (newline == std::string_view::npos) return 0;
      RawVolumeSpec spec;
      spec.path = dir.path() / filtered_name(payload.substr(0, newline));
      prizma::fuzz::write_file(spec.path, payload.substr(newline + 1));
      prizma::fuzz::accepts("load_raw_volume (named)", [&] { check_volume(load_raw_volume(spec)); });
      std::filesystem::remove(spec.path);
      break;
    }
    case 1: {
      if (payload.size() < 14) return 0;
      RawVolumeSpec spec;
      std::array<std::int32_t, 3> dims{};
      std::memcpy(dims.data(), payload.data(), sizeof(dims));
      spec.dims = {dims[0], dims[1], dims[2]};
      spec.type = static_cast<VoxelType>(static_cast<unsigned char>(payload[12]) % 4);
      spec.type_given = true;
      spec.big_endian = (payload[13] & 1) != 0;
      spec.path = dir.path() / "volume.raw";
      prizma::fuzz::write_file(spec.path, payload.substr(14));
      prizma::fuzz::accepts("load_raw_volume (given)", [&] { check_volume(load_raw_volume(spec)); });
      break;
    }
    case 2: {
      const auto path = dir.path() / "volume.nii";
      prizma::fuzz::write_file(path, payload);
      prizma::fuzz::accepts("load_nifti_volume (.nii)", [&] { check_volume(load_nifti_volume(path)); });
      break;
    }
    case 3: {
      const auto path = dir.path() / "volume.nii.gz";
      write_gzip(path, payload);
      prizma::fuzz::accepts("load_nifti_volume (.nii.gz)", [&] { check_volume(load_nifti_volume(path)); });
      break;
    }
    default: {
      const auto path = dir.path() / "volume.nii.gz";
      prizma::fuzz::write_file(path, payload);
      prizma::fuzz::accepts("load_nifti_volume (raw .nii.gz bytes)", [&] { check_volume(load_nifti_volume(path)); });
      break;
    }
  }
  return 0;
}
