// prizma/spectral/fnv1a.h: the one FNV-1a of the scene hash (bytes) and the pixel checksum (32-bit
// words). Both are stored in files and compared across versions, so the values are pinned: the
// published FNV-1a 64 test vectors for bytes, and for the checksum a small image whose value was
// computed independently (Python: h = basis; for each float's bit pattern w: h = (h ^ w) · prime mod 2⁶⁴).
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "prizma/spectral/fnv1a.h"
#include "prizma/spectral/spectral_exr.h"

namespace ps = prizma::spectral;

TEST(Fnv1a, BytesMatchThePublishedTestVectors) {
  // Fowler, Noll, Vo: FNV-1a 64 of "", "a" and "foobar".
  EXPECT_EQ(ps::Fnv1a().value(), 0xcbf29ce484222325ULL);
  ps::Fnv1a a;
  a.add_bytes("a", 1);
  EXPECT_EQ(a.value(), 0xaf63dc4c8601ec8cULL);
  ps::Fnv1a foobar;
  foobar.add_bytes("foo", 3);
  foobar.add_bytes("bar", 3);  // in pieces: the same as at once
  EXPECT_EQ(foobar.value(), 0x85944171f73967e8ULL);
  EXPECT_EQ(foobar.hex(), "85944171f73967e8");
}

TEST(Fnv1a, FloatWordsTakeOneStepPerValue) {
  // One XOR of the whole 32-bit pattern of 1.0f (0x3f800000) and one multiply: not four byte steps.
  const float one = 1.0f;
  ps::Fnv1a h;
  h.add_float_words(&one, 1);
  EXPECT_EQ(h.value(), (0xcbf29ce484222325ULL ^ 0x3f800000ULL) * 0x100000001b3ULL);
  EXPECT_EQ(h.value(), 0x2f63bdaad481b7dfULL);
  ps::Fnv1a bytes;
  bytes.add_bytes(&one, sizeof one);
  EXPECT_NE(bytes.value(), h.value());
  // A double is hashed as the float a reader gets.
  const double one_d = 1.0;
  ps::Fnv1a d;
  d.add_float_words(&one_d, 1);
  EXPECT_EQ(d.value(), h.value());
}

TEST(Fnv1a, PixelChecksumIsPinned) {
  // One light, 2×1 pixels, 3 bins, with variance: the transport term from cbf29ce484222325 plus the
  // variance term from 84222325cbf29ce4 (docs/spectral-exr.md), the same before and after the hash
  // moved into fnv1a.h.
  ps::SpectralImage img;
  img.width = 2;
  img.height = 1;
  img.bins = ps::BinLayout::linear(400, 700, 3);
  ps::TransportLayer l;
  l.name = "key";
  l.data = {0.25f, 0.5f, 1.0f, 2.0f, 0.0f, 3.5f};
  l.variance = {0.125f, 0.0f, 0.0625f, 1.0f, 0.5f, 0.25f};
  img.lights.push_back(l);
  EXPECT_EQ(ps::spectral_pixel_checksum(img), "fnv1a64-words-v2:bccb4af8c07eb801");
  img.lights[0].variance.clear();
  EXPECT_EQ(ps::spectral_pixel_checksum(img), "fnv1a64-words-v2:f16c1f33e4fd713d");
  // As written to a file and read back (the stored attribute is verified on reading).
  const std::filesystem::path p = std::filesystem::path(::testing::TempDir()) / "fnv1a_pinned.exr";
  ps::write_spectral_exr(p, img);
  EXPECT_NO_THROW(ps::read_spectral_exr(p));
  EXPECT_EQ(ps::spectral_pixel_checksum(ps::read_spectral_exr(p)), "fnv1a64-words-v2:f16c1f33e4fd713d");
  std::filesystem::remove(p);
}
