// NIfTI volumes: small files written with libnifti in every supported datatype (.nii and .nii.gz),
// scaling, spacing from pixdim, the refused kinds (complex, RGB, 4-D), corrupt and truncated files,
// and the real Colin27 template from Debian's mricron-data when it is installed.
#include <gtest/gtest.h>
#include <nifti1_io.h>
#include <sys/stat.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>

#include "missing_tool.h"
#include "prizma/render/volume.h"
#include "prizma/spectral/error.h"
#include "test_scene_util.h"

namespace prizma::render {
namespace {

using spectral::InputError;
using testing::ScratchDir;

// Writes a NIfTI-1 file of the given datatype and dims (4-D when nt > 1) whose voxel i holds
// value_of(i) converted to the datatype.
template <typename T>
void write_nifti(const std::filesystem::path& path, int datatype, std::array<int, 3> dims, int nt,
                 std::array<float, 3> spacing, double (*value_of)(std::size_t), float slope = 0.0f, float inter = 0.0f) {
  int d[8] = {nt > 1 ? 4 : 3, dims[0], dims[1], dims[2], nt, 1, 1, 1};
  nifti_image* nim = nifti_make_new_nim(d, datatype, 1);
  ASSERT_NE(nim, nullptr);
  nim->dx = nim->pixdim[1] = spacing[0];
  nim->dy = nim->pixdim[2] = spacing[1];
  nim->dz = nim->pixdim[3] = spacing[2];
  nim->scl_slope = slope;
  nim->scl_inter = inter;
  ASSERT_EQ(nifti_set_filenames(nim, path.c_str(), 0, 1), 0);
  T* data = static_cast<T*>(nim->data);
  for (std::size_t i = 0; i < nim->nvox; ++i) data[i] = static_cast<T>(value_of(i));
  nifti_image_write(nim);
  nifti_image_free(nim);
  ASSERT_TRUE(std::filesystem::exists(path)) << path;
}

double ramp(std::size_t i) { return static_cast<double>(i % 100) + 1.0; }
double signed_ramp(std::size_t i) { return static_cast<double>(i % 100) - 50.0; }

template <typename T>
void check_roundtrip(int datatype, double (*value_of)(std::size_t), const std::string& ext) {
  ScratchDir dir;
  const auto path = dir / ("v" + ext);
  write_nifti<T>(path, datatype, {4, 3, 2}, 1, {1.0f, 0.5f, 2.0f}, value_of);
  const Volume vol = load_nifti_volume(path);
  EXPECT_EQ(vol.dims, (std::array<int, 3>{4, 3, 2}));
  EXPECT_EQ(vol.spacing, (std::array<double, 3>{1.0, 0.5, 2.0}));
  ASSERT_EQ(vol.values.size(), 24u);
  for (std::size_t i = 0; i < 24; ++i) EXPECT_EQ(vol.values[i], static_cast<float>(static_cast<T>(value_of(i)))) << i;
}

TEST(NiftiVolume, ReadsEverySupportedDatatype) {
  for (const std::string ext : {".nii", ".nii.gz"}) {
    SCOPED_TRACE(ext);
    check_roundtrip<std::uint8_t>(DT_UINT8, ramp, ext);
    check_roundtrip<std::int8_t>(DT_INT8, signed_ramp, ext);
    check_roundtrip<std::uint16_t>(DT_UINT16, ramp, ext);
    check_roundtrip<std::int16_t>(DT_INT16, signed_ramp, ext);
    check_roundtrip<std::uint32_t>(DT_UINT32, ramp, ext);
    check_roundtrip<std::int32_t>(DT_INT32, signed_ramp, ext);
    check_roundtrip<float>(DT_FLOAT32, signed_ramp, ext);
    check_roundtrip<double>(DT_FLOAT64, signed_ramp, ext);
  }
}

TEST(NiftiVolume, AppliesSlopeAndIntercept) {
  ScratchDir dir;
  const auto path = dir / "scaled.nii";
  write_nifti<std::int16_t>(path, DT_INT16, {2, 2, 2}, 1, {1, 1, 1}, ramp, 0.5f, -10.0f);
  const Volume vol = load_nifti_volume(path);
  for (std::size_t i = 0; i < 8; ++i) EXPECT_FLOAT_EQ(vol.values[i], static_cast<float>(0.5 * ramp(i) - 10.0)) << i;
}

void expect_input_error(const std::filesystem::path& path, const std::string& fragment) {
  try {
    load_nifti_volume(path);
    FAIL() << "no error; expected one containing \"" << fragment << "\"";
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), path.string());
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(NiftiVolume, RefusesComplexRgbAnd4D) {
  ScratchDir dir;
  {
    int d[8] = {3, 2, 2, 2, 1, 1, 1, 1};
    for (int dt : {DT_COMPLEX64, DT_RGB24}) {
      nifti_image* nim = nifti_make_new_nim(d, dt, 1);
      ASSERT_NE(nim, nullptr);
      const auto path = dir / ("t" + std::to_string(dt) + ".nii");
      ASSERT_EQ(nifti_set_filenames(nim, path.c_str(), 0, 1), 0);
      nifti_image_write(nim);
      nifti_image_free(nim);
      expect_input_error(path, "unsupported NIfTI datatype");
    }
  }
  const auto four_d = dir / "series.nii.gz";
  write_nifti<std::uint8_t>(four_d, DT_UINT8, {2, 2, 2}, 3, {1, 1, 1}, ramp);
  expect_input_error(four_d, "3 volumes");
}

TEST(NiftiVolume, OneVolume4DIsAccepted) {
  ScratchDir dir;
  const auto path = dir / "one.nii";
  write_nifti<std::uint8_t>(path, DT_UINT8, {2, 3, 2}, 1, {1, 1, 1}, ramp);
  EXPECT_EQ(load_nifti_volume(path).dims, (std::array<int, 3>{2, 3, 2}));
}

TEST(NiftiVolume, CorruptAndTruncatedFilesAreInputErrors) {
  ScratchDir dir;
  // A valid gz file cut in half (the header survives, the voxels do not).
  const auto good = dir / "good.nii.gz";
  write_nifti<float>(good, DT_FLOAT32, {16, 16, 16}, 1, {1, 1, 1}, ramp);
  std::ifstream in(good, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GT(bytes.size(), 200u);
  expect_input_error(dir.write("half.nii.gz", bytes.substr(0, bytes.size() / 2)), "corrupt or truncated");
  // Only the first 40 bytes: not even the header.
  expect_input_error(dir.write("stub.nii.gz", bytes.substr(0, 40)), "NIfTI");
  // Garbage bytes and an empty file.
  expect_input_error(dir.write("garbage.nii.gz", std::string(1000, 'x')), "NIfTI");
  expect_input_error(dir.write("garbage.nii", std::string(1000, '\x07')), "NIfTI");
  expect_input_error(dir.write("empty.nii", ""), "NIfTI");
  // An uncompressed file truncated inside the voxels.
  const auto plain = dir / "plain.nii";
  write_nifti<std::uint16_t>(plain, DT_UINT16, {8, 8, 8}, 1, {1, 1, 1}, ramp);
  std::filesystem::resize_file(plain, 352 + 500);
  expect_input_error(plain, "corrupt or truncated");
  expect_input_error(dir / "absent.nii", "no such file");
}

// Reads a file's bytes; writes bytes back.
std::string read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}
void put_float(std::string& bytes, std::size_t offset, float v) { std::memcpy(bytes.data() + offset, &v, sizeof v); }

TEST(NiftiVolume, ZeroAndNegativePixdim) {
  // A negative pixdim gives its magnitude; a 0 on an axis of one voxel is harmless (spacing 1).
  ScratchDir dir;
  const auto path = dir / "flat.nii";
  write_nifti<std::uint8_t>(path, DT_UINT8, {2, 2, 1}, 1, {2.0f, -3.0f, 0.0f}, ramp);
  EXPECT_EQ(load_nifti_volume(path).spacing, (std::array<double, 3>{2.0, 3.0, 1.0}));
}

// issue 11: pixdim 0, NaN or inf on an axis of more than one voxel was read as 1 (libnifti turns
// 0 into 1); docs/scene-format.md says it is refused.
TEST(NiftiVolume, RefusesZeroNanOrInfinitePixdimOnARealAxis) {
  ScratchDir dir;
  const auto path = dir / "v.nii";
  write_nifti<std::uint8_t>(path, DT_UINT8, {2, 2, 2}, 1, {1, 1, 1}, ramp);
  const std::string good = read_bytes(path);
  for (float bad : {0.0f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    std::string bytes = good;
    put_float(bytes, 76 + 4 * 2, bad);  // pixdim[2]
    expect_input_error(dir.write("bad.nii", bytes), "pixdim[2] must be a finite non-zero voxel size");
  }
}

// issue 11: a negative vox_offset read the voxels from offset 348 (shifted by 4 bytes).
TEST(NiftiVolume, RefusesAVoxOffsetInsideTheHeader) {
  ScratchDir dir;
  const auto path = dir / "v.nii";
  write_nifti<std::uint8_t>(path, DT_UINT8, {2, 2, 2}, 1, {1, 1, 1}, ramp);
  for (float bad : {-4.0f, 0.0f, 100.0f, 352.5f}) {
    std::string bytes = read_bytes(path);
    put_float(bytes, 108, bad);
    expect_input_error(dir.write("off.nii", bytes), "vox_offset");
  }
}

// issue 11: a .nii.gz whose gzip trailer (CRC-32 and length) is missing was accepted.
TEST(NiftiVolume, RefusesAGzipStreamWithoutItsTrailer) {
  ScratchDir dir;
  const auto path = dir / "v.nii.gz";
  write_nifti<float>(path, DT_FLOAT32, {4, 4, 4}, 1, {1, 1, 1}, ramp);
  const std::string bytes = read_bytes(path);
  EXPECT_NO_THROW(load_nifti_volume(path));
  expect_input_error(dir.write("cut.nii.gz", bytes.substr(0, bytes.size() - 8)), "gzip");
  std::string bad_crc = bytes;
  bad_crc[bad_crc.size() - 6] = static_cast<char>(bad_crc[bad_crc.size() - 6] ^ 0x5a);
  // A wrong CRC: refused by libnifti's header read when the stream is this short, by the trailer
  // check otherwise.
  expect_input_error(dir.write("crc.nii.gz", bad_crc), "");
}

// issue 11: a FIFO blocked the loader forever; non-regular files are refused up front.
TEST(NiftiVolume, RefusesNonRegularFiles) {
  ScratchDir dir;
  ASSERT_EQ(::mkfifo((dir / "pipe.nii").c_str(), 0600), 0);
  expect_input_error(dir / "pipe.nii", "FIFO");
  expect_input_error("/dev/zero", "character device");
}

TEST(NiftiVolume, ReadsColin27Template) {
  // Debian's mricron-data: ch2better.nii.gz is 301×370×316 uint8 at 0.5 mm (values 0–130);
  // ch2.nii.gz is 181×217×181 at 1 mm. Reference: their headers, read with Python's gzip.
  const std::filesystem::path better = "/usr/share/mricron/templates/ch2better.nii.gz";
  const std::filesystem::path ch2 = "/usr/share/mricron/templates/ch2.nii.gz";
  if (!std::filesystem::exists(better) || !std::filesystem::exists(ch2)) PRIZMA_MISSING_TOOL("mricron-data");
  const Volume vb = load_nifti_volume(better);
  EXPECT_EQ(vb.dims, (std::array<int, 3>{301, 370, 316}));
  EXPECT_EQ(vb.spacing, (std::array<double, 3>{0.5, 0.5, 0.5}));
  EXPECT_EQ(*std::max_element(vb.values.begin(), vb.values.end()), 130.0f);
  const Volume v2 = load_nifti_volume(ch2);
  EXPECT_EQ(v2.dims, (std::array<int, 3>{181, 217, 181}));
  EXPECT_EQ(v2.spacing, (std::array<double, 3>{1.0, 1.0, 1.0}));
}

}  // namespace
}  // namespace prizma::render
