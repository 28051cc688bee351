// NIfTI-1 volumes (.nii, .nii.gz) through libnifti. The header is read and checked first (type,
// dimensions, memory), then the voxels; every libnifti return is checked.
#include <nifti1_io.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include "prizma/render/volume.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/input_file.h"
#include "prizma/spectral/stderr_capture.h"
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

// " (libnifti: <what it printed>)", or "".
std::string library_said(const std::string& printed) {
  return printed.empty() ? std::string() : " (libnifti: " + printed + ")";
}

// The header exactly as stored: libnifti's nifti_image turns a pixdim of 0 into 1 and a negative
// vox_offset into 348, so the checks the format requires are made here.
void check_raw_header(const std::string& input) {
  int swapped = 0;
  spectral::StderrCapture capture;
  nifti_1_header* h = nifti_read_header(input.c_str(), &swapped, 1);
  const std::string printed = capture.finish();
  if (h == nullptr) {
    throw InputError(input, "not a readable NIfTI-1 file (corrupt, truncated or another format)" + library_said(printed));
  }
  const nifti_1_header hdr = *h;
  std::free(h);
  const int ndim = std::clamp<int>(hdr.dim[0], 0, 7);
  for (int a = 1; a <= std::min(ndim, 3); ++a) {
    const float p = hdr.pixdim[a];
    if (hdr.dim[a] > 1 && !(std::isfinite(p) && p != 0.0f)) {
      throw InputError(input, "pixdim[" + std::to_string(a) + "] must be a finite non-zero voxel size on an axis of " +
                                  std::to_string(hdr.dim[a]) + " voxels (got " + std::to_string(p) + ")");
    }
  }
  const bool one_file = std::string(hdr.magic, 3) == "n+1";
  const float off = hdr.vox_offset;
  const float min_off = one_file ? 352.0f : 0.0f;
  if (!(std::isfinite(off) && off >= min_off && off == std::floor(off))) {
    throw InputError(input, "vox_offset " + std::to_string(off) + " is invalid (a " +
                                (one_file ? std::string("single-file .nii needs a whole number ≥ 352")
                                          : std::string(".hdr/.img pair needs a whole number ≥ 0")) + ")");
  }
}

// Reorders the voxels (axis permutation and flips, no resampling) so that +x, +y, +z point to the
// patient's Right, Anterior and Superior by the sform (preferred when sform_code > 0) or the qform;
// libnifti's nifti_mat44_to_orientation names the closest anatomical direction of each file axis.
// Returns the note for the render's log.
std::string orient_ras(const nifti_image& nim, Volume& vol) {
  const char* source = nullptr;
  mat44 m{};
  if (nim.sform_code > 0) {
    source = "sform";
    m = nim.sto_xyz;
  } else if (nim.qform_code > 0) {
    source = "qform";
    m = nim.qto_xyz;
  } else {
    return "NIfTI orientation: none (sform_code and qform_code are 0): file axes kept as +x, +y, +z";
  }
  int code[3] = {0, 0, 0};
  nifti_mat44_to_orientation(m, &code[0], &code[1], &code[2]);
  // Code c (NIFTI_L2R = 1 … NIFTI_S2I = 6): world axis (c − 1) / 2 (R, A, S), positive when c is odd.
  static const char* const kDir[6] = {"R", "L", "A", "P", "S", "I"};
  int out_of[3] = {-1, -1, -1};  // world axis → file axis
  bool flip[3] = {false, false, false};
  std::string file_axes;
  double worst_cos = 1.0;  // the cosine of the largest angle between a file axis and its nearest world axis
  for (int i = 0; i < 3; ++i) {
    if (code[i] < 1 || code[i] > 6) return std::string("NIfTI orientation: the ") + source + " is degenerate: file axes kept";
    const int w = (code[i] - 1) / 2;
    if (out_of[w] >= 0) return std::string("NIfTI orientation: the ") + source + " is degenerate: file axes kept";
    out_of[w] = i;
    flip[w] = code[i] % 2 == 0;
    file_axes += std::string(i == 0 ? "" : " ") + "+" + "ijk"[i] + "→" + kDir[code[i] - 1];
    double len = 0.0;
    for (int r = 0; r < 3; ++r) len += static_cast<double>(m.m[r][i]) * m.m[r][i];
    if (len > 0.0) worst_cos = std::min(worst_cos, std::abs(static_cast<double>(m.m[w][i])) / std::sqrt(len));
  }
  // An oblique file (tilted slices) is snapped, not resampled: the anatomy comes out rotated by up to
  // that angle, which a user must hear without asking (--verbose): a warning on every render.
  const bool oblique = worst_cos < 0.9999;
  if (oblique) {
    char angle[32];
    std::snprintf(angle, sizeof angle, "%.1f", std::acos(worst_cos) * 180.0 / std::numbers::pi);
    vol.warnings.push_back(vol.source + ": NIfTI orientation: the " + source + " is oblique (a file axis is " + angle +
                           "° from the nearest anatomical axis); its axes were snapped to the nearest (file " + file_axes +
                           "), not resampled, so the volume is rotated by up to " + angle + "° from the patient's frame");
  }
  const std::array<int, 3> src = vol.dims;
  std::array<int, 3> dims{};
  std::array<double, 3> spacing{};
  for (int w = 0; w < 3; ++w) {
    dims[w] = src[out_of[w]];
    spacing[w] = vol.spacing[out_of[w]];
  }
  const bool identity = out_of[0] == 0 && out_of[1] == 1 && out_of[2] == 2 && !flip[0] && !flip[1] && !flip[2];
  if (!identity) {
    std::vector<float> out(vol.values.size());
    const std::size_t stride[3] = {1, static_cast<std::size_t>(src[0]), static_cast<std::size_t>(src[0]) * src[1]};
    std::size_t k = 0;
    for (int z = 0; z < dims[2]; ++z)
      for (int y = 0; y < dims[1]; ++y)
        for (int x = 0; x < dims[0]; ++x) {
          const int c[3] = {x, y, z};
          std::size_t from = 0;
          for (int w = 0; w < 3; ++w) from += stride[out_of[w]] * static_cast<std::size_t>(flip[w] ? dims[w] - 1 - c[w] : c[w]);
          out[k++] = vol.values[from];
        }
    vol.values = std::move(out);
    vol.dims = dims;
    vol.spacing = spacing;
  }
  return std::string("NIfTI orientation (") + source + "): file " + file_axes +
         (identity ? ", kept as" : ", reordered to") + " +x→R +y→A +z→S (world x = patient right, y = anterior, z = superior)" +
         (oblique ? "; oblique axes snapped to the nearest, not resampled" : "");
}

std::string datatype_name(int dt) {
  const char* s = nifti_datatype_to_string(dt);
  return s != nullptr ? std::string(s) : "datatype " + std::to_string(dt);
}

}  // namespace

// long on purpose: the header checks, the guarded chunked read and the voxel conversion in the order a file is trusted.
Volume load_nifti_volume(const std::filesystem::path& path) {
  const std::string input = path.string();
  spectral::require_regular_file(path, "a NIfTI file");

  // libnifti reports failures on stderr at debug level ≥ 1; we report them ourselves.
  nifti_set_debug_level(0);
  check_raw_header(input);
  spectral::StderrCapture capture;
  NiftiPtr nim(nifti_image_read(input.c_str(), 0));
  const std::string printed = capture.finish();
  if (!nim) {
    throw InputError(input, "not a readable NIfTI-1 file (corrupt, truncated or another format)" + library_said(printed));
  }

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
    // zlib directly (it reads plain files too), so that a .gz stream cut before its trailer (the
    // CRC and length that prove the data complete) is refused, not taken as read.
    const bool gz = nifti_is_gzfile(nim->iname) != 0;
    gzFile fp = gzopen(nim->iname, "rb");
    if (fp == nullptr) throw InputError(input, "cannot open the voxel data " + std::string(nim->iname));
    std::size_t got = 0;
    if (gzseek(fp, static_cast<z_off_t>(nim->iname_offset), SEEK_SET) >= 0) {
      while (got < nbytes) {
        const std::size_t want = std::min(kChunkBytes, nbytes - got);
        if (raw.capacity() < got + want) raw.reserve(std::min(nbytes, std::max(got + want, 2 * raw.capacity())));
        raw.resize(got + want);
        const int n = gzread(fp, raw.data() + got, static_cast<unsigned>(want));
        if (n > 0) got += static_cast<std::size_t>(n);
        if (n != static_cast<int>(want)) break;
      }
    }
    bool stream_ok = true;
    if (gz && got == nbytes) {
      // Read on to the end of the stream: zlib checks the trailer there.
      unsigned char rest[4096];
      int n = 0;
      while ((n = gzread(fp, rest, sizeof rest)) > 0) {
      }
      int err = Z_OK;
      gzerror(fp, &err);
      stream_ok = n == 0 && (err == Z_OK || err == Z_STREAM_END);
    }
    gzclose(fp);
    if (!stream_ok) {
      throw InputError(input, "the gzip stream is incomplete or damaged (no valid gzip trailer after the voxels)");
    }
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
  vol.orientation = orient_ras(*nim, vol);
  return vol;
}

}  // namespace prizma::render
