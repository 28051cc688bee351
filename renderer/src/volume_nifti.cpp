// NIfTI-1 volumes (.nii, .nii.gz) through libnifti. The header is read and checked first (type,
// dimensions, memory), then the voxels; every libnifti return is checked.
#include <nifti1_io.h>
#include <znzlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>

#include "prizma/render/volume.h"
#include "prizma/spectral/error.h"
#include "volume_budget.h"

namespace prizma::render {

using spectral::InputError;

namespace {

struct NiftiFree {
  void operator()(nifti_image* nim) const { nifti_image_free(nim); }
};
using NiftiPtr = std::unique_ptr<nifti_image, NiftiFree>;

template <typename T>
void convert(const void* data, std::size_t n, double slope, double inter, std::vector<float>& out) {
  const T* p = static_cast<const T*>(data);
  if (slope != 0.0) {
    for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<float>(slope * static_cast<double>(p[i]) + inter);
  } else {
    for (std::size_t i = 0; i < n; ++i) out[i] = static_cast<float>(p[i]);
  }
}

std::string datatype_name(int dt) {
  const char* s = nifti_datatype_to_string(dt);
  return s != nullptr ? std::string(s) : "datatype " + std::to_string(dt);
}

}  // namespace

Volume load_nifti_volume(const std::filesystem::path& path) {
  const std::string input = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(input, "no such file");

  // libnifti reports failures on stderr at debug level ≥ 1; we report them ourselves.
  nifti_set_debug_level(0);
  NiftiPtr nim(nifti_image_read(input.c_str(), 0));
  if (!nim) throw InputError(input, "not a readable NIfTI-1 file (corrupt, truncated or another format)");

  // Supported voxel types only.
  const int dt = nim->datatype;
  std::size_t file_bytes = 0;
  switch (dt) {
    case DT_UINT8: case DT_INT8: file_bytes = 1; break;
    case DT_UINT16: case DT_INT16: file_bytes = 2; break;
    case DT_UINT32: case DT_INT32: case DT_FLOAT32: file_bytes = 4; break;
    case DT_FLOAT64: file_bytes = 8; break;
    default:
      throw InputError(input, "unsupported NIfTI datatype " + datatype_name(dt) +
                                  " (supported: UINT8, INT8, UINT16, INT16, UINT32, INT32, FLOAT32, FLOAT64; "
                                  "complex and RGB volumes are not scalar)");
  }
  if (nim->ndim < 1 || nim->ndim > 7) throw InputError(input, "invalid number of dimensions " + std::to_string(nim->ndim));
  const long long extra = static_cast<long long>(std::max(nim->nt, 1)) * std::max(nim->nu, 1) *
                          std::max(nim->nv, 1) * std::max(nim->nw, 1);
  if (nim->ndim > 3 && extra > 1) {
    throw InputError(input, "4-D or higher NIfTI with " + std::to_string(extra) +
                                " volumes is not supported (only one 3-D volume)");
  }
  const std::array<int, 3> dims{nim->nx, nim->ny, std::max(nim->nz, 1)};
  const std::size_t count = detail::check_volume_fits(dims, file_bytes, input);

  // Spacing from pixdim (absolute; libnifti already reads a pixdim of 0 as 1).
  std::array<double, 3> spacing{nim->dx, nim->dy, nim->dz};
  for (int a = 0; a < 3; ++a) {
    spacing[a] = std::abs(spacing[a]);
    if (!std::isfinite(spacing[a]) || spacing[a] <= 0.0) {
      if (dims[a] == 1) {
        spacing[a] = 1.0;
      } else {
        throw InputError(input, "pixdim[" + std::to_string(a + 1) + "] must be positive (got " +
                                    std::to_string(spacing[a]) + ")");
      }
    }
  }
  double slope = nim->scl_slope;
  double inter = nim->scl_inter;
  if (!std::isfinite(slope)) slope = 0.0;
  if (!std::isfinite(inter)) inter = 0.0;

  if (static_cast<std::size_t>(nim->nvox) != count || static_cast<std::size_t>(nim->nbyper) != file_bytes) {
    throw InputError(input, "inconsistent header: " + std::to_string(nim->nvox) + " voxels of " +
                                std::to_string(nim->nbyper) + " bytes");
  }

  // Voxels, read here rather than by nifti_image_load, which zero-fills a short read and succeeds.
  if (nim->iname == nullptr || nim->iname_offset < 0) throw InputError(input, "header names no voxel data");
  // The buffer grows only as data arrives (in chunks, capacity doubling up to the declared size), so
  // a header that claims far more voxels than the file holds costs one chunk, not the claimed size.
  const std::size_t nbytes = count * file_bytes;
  constexpr std::size_t kChunkBytes = std::size_t{64} << 20;
  std::vector<unsigned char> raw;
  {
    znzFile fp = znzopen(nim->iname, "rb", nifti_is_gzfile(nim->iname));
    if (znz_isnull(fp)) throw InputError(input, "cannot open the voxel data " + std::string(nim->iname));
    std::size_t got = 0;
    if (znzseek(fp, nim->iname_offset, SEEK_SET) >= 0) {
      while (got < nbytes) {
        const std::size_t want = std::min(kChunkBytes, nbytes - got);
        if (raw.capacity() < got + want) raw.reserve(std::min(nbytes, std::max(got + want, 2 * raw.capacity())));
        raw.resize(got + want);
        const std::size_t n = znzread(raw.data() + got, 1, want, fp);
        got += n;
        if (n != want) break;
      }
    }
    znzclose(fp);
    if (got != nbytes) {
      throw InputError(input, "cannot read the voxel data: file corrupt or truncated (needs " + std::to_string(nbytes) +
                                  " bytes at offset " + std::to_string(nim->iname_offset) + ")");
    }
  }
  if (nim->swapsize > 1 && nim->byteorder != nifti_short_order()) {
    nifti_swap_Nbytes(count, nim->swapsize, raw.data());
  }
  const void* data = raw.data();
  Volume vol;
  vol.dims = dims;
  vol.spacing = spacing;
  vol.source = input;
  vol.values.resize(count);
  switch (dt) {
    case DT_UINT8: convert<std::uint8_t>(data, count, slope, inter, vol.values); break;
    case DT_INT8: convert<std::int8_t>(data, count, slope, inter, vol.values); break;
    case DT_UINT16: convert<std::uint16_t>(data, count, slope, inter, vol.values); break;
    case DT_INT16: convert<std::int16_t>(data, count, slope, inter, vol.values); break;
    case DT_UINT32: convert<std::uint32_t>(data, count, slope, inter, vol.values); break;
    case DT_INT32: convert<std::int32_t>(data, count, slope, inter, vol.values); break;
    case DT_FLOAT32: convert<float>(data, count, slope, inter, vol.values); break;
    case DT_FLOAT64: convert<double>(data, count, slope, inter, vol.values); break;
    default: break;
  }
  return vol;
}

}  // namespace prizma::render
