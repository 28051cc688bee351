// Raw volume files: every voxel type, both byte orders, dimensions and type from the file name,
// and the input errors (size mismatch, truncation, unparseable name, bad dims/spacing, too large).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>

#include "prizma/render/volume.h"
#include "prizma/spectral/error.h"
#include "test_scene_util.h"

namespace prizma::render {
namespace {

using spectral::InputError;
using testing::ScratchDir;

// Bytes of `values` as type T in the given byte order.
template <typename T>
std::string encode(const std::vector<double>& values, bool big_endian) {
  std::string bytes;
  for (double v : values) {
    T t = static_cast<T>(v);
    unsigned char b[sizeof(T)];
    std::memcpy(b, &t, sizeof(T));
    if (big_endian) std::reverse(b, b + sizeof(T));  // this machine is little-endian (x86-64)
    bytes.append(reinterpret_cast<const char*>(b), sizeof(T));
  }
  return bytes;
}

// 3×2×2 values, x fastest; distinct and representable in every type (int16 gets negatives).
std::vector<double> sample_values(bool negative) {
  std::vector<double> v;
  for (int i = 0; i < 12; ++i) v.push_back(negative && i % 3 == 0 ? -300.0 - i : 7.0 * i + (i == 11 ? 170 : 0));
  return v;
}

template <typename T>
void check_type(VoxelType type, bool negative, bool big_endian) {
  ScratchDir dir;
  const auto values = sample_values(negative);
  RawVolumeSpec spec;
  spec.path = dir.write("v.raw", encode<T>(values, big_endian));
  spec.dims = {3, 2, 2};
  spec.type = type;
  spec.type_given = true;
  spec.big_endian = big_endian;
  spec.spacing = {1.0, 2.0, 0.5};
  const Volume vol = load_raw_volume(spec);
  ASSERT_EQ(vol.dims, (std::array<int, 3>{3, 2, 2}));
  EXPECT_EQ(vol.spacing, (std::array<double, 3>{1.0, 2.0, 0.5}));
  ASSERT_EQ(vol.values.size(), values.size());
  for (std::size_t i = 0; i < values.size(); ++i) EXPECT_EQ(vol.values[i], static_cast<float>(static_cast<T>(values[i]))) << i;
  // x fastest: at(x, y, z) = values[(z·2 + y)·3 + x].
  EXPECT_EQ(vol.at(2, 1, 1), static_cast<float>(static_cast<T>(values[11])));
  EXPECT_EQ(vol.at(1, 0, 1), static_cast<float>(static_cast<T>(values[7])));
}

TEST(RawVolume, ReadsEveryTypeInBothByteOrders) {
  for (bool big : {false, true}) {
    SCOPED_TRACE(big ? "big-endian" : "little-endian");
    check_type<std::uint8_t>(VoxelType::U8, false, big);
    check_type<std::uint16_t>(VoxelType::U16, false, big);
    check_type<std::int16_t>(VoxelType::I16, true, big);
    check_type<float>(VoxelType::F32, true, big);
  }
}

TEST(RawVolume, BigEndianDiffersFromLittle) {
  // The same bytes read in the other order give other values (0x0102 = 258 vs 0x0201 = 513).
  ScratchDir dir;
  RawVolumeSpec spec;
  spec.path = dir.write("v_1x1x1_uint16.raw", std::string("\x01\x02", 2));
  EXPECT_EQ(load_raw_volume(spec).values[0], 513.0f);
  spec.big_endian = true;
  EXPECT_EQ(load_raw_volume(spec).values[0], 258.0f);
}

TEST(RawVolume, ParsesDimsAndTypeFromTheName) {
  ScratchDir dir;
  struct Case {
    std::string name;
    std::size_t bytes_per_voxel;
    std::array<int, 3> dims;
  };
  for (const Case& c : {Case{"chameleon_4x3x2_uint16.raw", 2, {4, 3, 2}}, Case{"a_2x2x2_uint8.raw", 1, {2, 2, 2}},
                        Case{"b_3x1x2_int16.raw", 2, {3, 1, 2}}, Case{"c_1x2x3_float32.raw", 4, {1, 2, 3}},
                        Case{"d_2x2x1_u16.raw", 2, {2, 2, 1}}, Case{"e_2x1x1_f32", 4, {2, 1, 1}},
                        Case{"f_1x1x2_I16.raw", 2, {1, 1, 2}}}) {
    SCOPED_TRACE(c.name);
    RawVolumeSpec spec;
    const std::size_t n = static_cast<std::size_t>(c.dims[0]) * c.dims[1] * c.dims[2];
    spec.path = dir.write(c.name, std::string(n * c.bytes_per_voxel, '\0'));
    const Volume vol = load_raw_volume(spec);
    EXPECT_EQ(vol.dims, c.dims);
    EXPECT_EQ(vol.values.size(), n);
  }
}

TEST(RawVolume, TypeFromNameDecodesValues) {
  // int16 from the name: 0xFFFF little-endian is −1, not 65535.
  ScratchDir dir;
  RawVolumeSpec spec;
  spec.path = dir.write("v_1x1x1_int16.raw", std::string("\xff\xff", 2));
  EXPECT_EQ(load_raw_volume(spec).values[0], -1.0f);
}

void expect_input_error(const RawVolumeSpec& spec, const std::string& fragment) {
  try {
    load_raw_volume(spec);
    FAIL() << "no error; expected one containing \"" << fragment << "\"";
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), spec.path.string());
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(RawVolume, RejectsSizeMismatch) {
  ScratchDir dir;
  RawVolumeSpec spec;
  spec.path = dir.write("v_2x2x2_uint16.raw", std::string(15, '\0'));  // 16 expected
  expect_input_error(spec, "does not match");
  spec.path = dir.write("w_2x2x2_uint16.raw", std::string(17, '\0'));
  expect_input_error(spec, "does not match");
}

TEST(RawVolume, RejectsUnparseableName) {
  ScratchDir dir;
  RawVolumeSpec spec;
  spec.path = dir.write("volume.raw", std::string(8, '\0'));
  expect_input_error(spec, "cannot parse");
  spec.path = dir.write("v_2x2x2_uint12.raw", std::string(8, '\0'));
  expect_input_error(spec, "cannot parse");
  // Dims given but no type: the name must still supply the type.
  spec.dims = {2, 2, 2};
  spec.path = dir.write("plain.raw", std::string(8, '\0'));
  expect_input_error(spec, "cannot parse");
}

TEST(RawVolume, RejectsMissingFile) {
  ScratchDir dir;
  RawVolumeSpec spec;
  spec.path = dir / "absent_2x2x2_uint8.raw";
  expect_input_error(spec, "no such file");
}

TEST(RawVolume, RejectsNonPositiveDimsAndSpacing) {
  ScratchDir dir;
  RawVolumeSpec spec;
  spec.path = dir.write("v.raw", std::string(8, '\0'));
  spec.type_given = true;
  spec.dims = {2, -2, 2};
  expect_input_error(spec, "positive");
  spec.dims = {2, 0, 2};
  expect_input_error(spec, "positive");
  spec.dims = {2, 2, 2};
  spec.spacing = {1.0, 0.0, 1.0};
  expect_input_error(spec, "spacing");
  spec.spacing = {1.0, -1.0, 1.0};
  expect_input_error(spec, "spacing");
}

TEST(RawVolume, RejectsVolumesTooLargeBeforeAllocating) {
  ScratchDir dir;
  RawVolumeSpec spec;
  // 2^31−1 cubed overflows 64 bits; 100000³ floats is 4 PB: neither can be allocated, and the
  // check must come before the file size (the file is tiny).
  spec.path = dir.write("huge_2147483647x2147483647x2147483647_uint8.raw", std::string(8, '\0'));
  expect_input_error(spec, "too large");
  spec.path = dir.write("big_100000x100000x100000_float32.raw", std::string(8, '\0'));
  expect_input_error(spec, "too large");
}

TEST(RawVolume, RejectsTruncatedFileWithExplicitDims) {
  ScratchDir dir;
  RawVolumeSpec spec;
  spec.path = dir.write("t.raw", std::string(100, '\0'));
  spec.dims = {8, 8, 8};
  spec.type = VoxelType::F32;
  spec.type_given = true;
  expect_input_error(spec, "does not match");
}

}  // namespace
}  // namespace prizma::render
