// Damaged spectral EXR files: bytes that are not an EXR, truncation, header sizes that disagree with
// the file (the OpenEXR header guard), non-regular files, and the checksum over what a reader gets.
#include "spectral_exr_test_support.h"

using namespace prizma::spectral;
using namespace prizma::spectral::exr_test;

namespace {

// The checksum's value, after its kind.
std::uint64_t checksum_value(const std::string& checksum) {
  return std::stoull(checksum.substr(checksum.rfind(':') + 1), nullptr, 16);
}

}  // namespace

TEST_F(SpectralExr, RefusesNonExrBytes) {
  const fs::path p = file("text.exr");
  std::ofstream(p) << "this is not an image\n";
  const std::string err = read_error(p);
  EXPECT_NE(err.find(p.string()), std::string::npos) << err;
  EXPECT_NE(err.find("not an OpenEXR file"), std::string::npos) << err;
  EXPECT_NE(read_error(file("missing.exr")).find("no such file"), std::string::npos);
}

TEST_F(SpectralExr, RefusesTruncatedFile) {
  const SpectralImage img = make_image(32, 32, BinLayout::linear(400, 700, 8), {"a", "b"});
  const fs::path p = file("cut.exr");
  write_spectral_exr(p, img);
  const auto size = fs::file_size(p);
  // Cut in the pixel data, and cut inside the header.
  for (const auto keep : {size * 2 / 3, std::uintmax_t{40}}) {
    const fs::path cut = file("cut-" + std::to_string(keep) + ".exr");
    fs::copy_file(p, cut);
    fs::resize_file(cut, keep);
    const std::string err = read_error(cut);
    EXPECT_NE(err.find(cut.string()), std::string::npos) << err;
    EXPECT_EQ(err.find("(no InputError)"), std::string::npos) << "kept " << keep << " of " << size;
  }
}

// Damaged headers: refused before OpenEXR allocates what they claim (it trusts the sizes) or reads
// the rest of the header out of step, with a message naming the attribute. A string attribute
// declaring ~1.9 GB (also as a type OpenEXR does not know, read as opaque bytes), a string vector
// holding a 1 GB string, a 60000 × 2 preview image in 24 bytes, a channel list whose size is one byte
// more than its content, and a data window (box2i) declared with 17 bytes.
TEST_F(SpectralExr, RefusesHeaderSizesThatDisagreeWithTheFile) {
  const SpectralImage img = make_image(4, 4, BinLayout::linear(400, 700, 3), {"a"});
  const fs::path plain = file("plain.exr");
  write_spectral_exr(plain, img);
  const fs::path extra = rewrite_header(plain, file("extra.exr"), [](Imf::Header& h) {
    h.insert("notes", Imf::StringVectorAttribute({"abc", "de"}));
    h.setPreviewImage(Imf::PreviewImage(2, 2));
  });
  std::ifstream in(extra, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_NO_THROW(read_spectral_exr(extra));

  struct Damage {
    std::string key;       // attribute name and type name, each with its terminating NUL
    std::size_t offset;    // of the patched int32 after the key (0: the attribute's own size)
    std::uint32_t value;   // written little-endian, as the file is
    std::string new_type;  // when not empty: the type name replaced by this (same length)
    std::string expect;
  };
  const auto nul = std::string(1, '\0');
  const std::string version = "prizma:version" + nul + "string" + nul;
  const std::string channels = "channels" + nul + "chlist" + nul;
  const auto chlist_size = static_cast<std::uint32_t>(le_u32_at(bytes, bytes.find(channels) + channels.size()));
  const std::vector<Damage> cases = {
      {version, 0, 1929405800u, "", "\"prizma:version\" (string, 1929405800 bytes) is larger than the"},
      {version, 0, 1929405800u, "strinX", "\"prizma:version\" (strinX, 1929405800 bytes) is larger than the"},
      {"notes" + nul + "stringvector" + nul, 4, 1000000000u, "",
       "\"notes\" (stringvector, 13 bytes) holds a string of 1000000000 bytes"},
      {"preview" + nul + "preview" + nul, 4, 60000u, "", "\"preview\" (preview, 24 bytes) holds a 60000x2 preview"},
      {channels, 0, chlist_size + 1, "",
       "\"channels\" (chlist, " + std::to_string(chlist_size + 1) + " bytes) is a channel list that ends before"},
      {"dataWindow" + nul + "box2i" + nul, 0, 17u, "", "\"dataWindow\" (box2i, 17 bytes) should have 16 bytes"},
  };
  int k = 0;
  for (const Damage& d : cases) {
    const auto at = bytes.find(d.key);
    ASSERT_NE(at, std::string::npos) << d.key;
    std::string damaged = bytes;
    if (!d.new_type.empty()) damaged.replace(at + d.key.size() - d.new_type.size() - 1, d.new_type.size(), d.new_type);
    const std::uint32_t v = d.value;
    std::memcpy(&damaged[at + d.key.size() + d.offset], &v, sizeof v);
    const fs::path out = file("damaged-" + std::to_string(k++) + ".exr");
    std::ofstream(out, std::ios::binary) << damaged;
    const std::string err = read_error(out);
    EXPECT_NE(err.find(out.string() + ": header attribute "), std::string::npos) << err;
    EXPECT_NE(err.find(d.expect), std::string::npos) << err;
  }
}

TEST_F(SpectralExr, WritesChecksumOfWhatAReaderGets) {
  for (const ExrPixelType type : {ExrPixelType::Float, ExrPixelType::Half}) {
    SpectralImage img = make_image(8, 4, BinLayout::linear(400, 700, 5), {"key", "fill"}, /*variance=*/true);
    const fs::path p = file(type == ExrPixelType::Half ? "half.exr" : "float.exr");
    ExrWriteOptions opts;
    opts.pixel_type = type;
    opts.write_variance = true;
    write_spectral_exr(p, img, opts);
    Imf::InputFile in(p.c_str());
    const auto* attr = in.header().findTypedAttribute<Imf::StringAttribute>("prizma:checksum");
    ASSERT_NE(attr, nullptr);
    EXPECT_EQ(attr->value().rfind("fnv1a64-words-v2:", 0), 0u) << attr->value();
    EXPECT_EQ(attr->value().size(), std::string("fnv1a64-words-v2:").size() + 16);
    EXPECT_NO_THROW(read_spectral_exr(p));  // half: the checksum is of the values after conversion
  }
}

// PIZ has no check of its own: without the checksum some damaged files read as other finite values.
// Every single-byte change in the pixel part of the file must either be refused or change nothing.
TEST_F(SpectralExr, DamagedPixelDataIsNeverReadSilently) {
  const SpectralImage img = make_image(32, 32, BinLayout::linear(400, 700, 8), {"key", "fill"});
  const fs::path p = file("good.exr");
  write_spectral_exr(p, img);
  std::string bytes;
  {
    std::ifstream in(p, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  int refused_by_checksum = 0, refused_otherwise = 0, unchanged = 0;
  const std::size_t first = bytes.size() / 4;  // the header and offset table are far smaller
  ASSERT_GT(bytes.size(), 8000u);
  for (std::size_t at = first; at < bytes.size(); at += 61) {
    std::string damaged = bytes;
    damaged[at] = static_cast<char>(damaged[at] ^ 0x10);
    const fs::path q = file("damaged.exr");
    {
      std::ofstream out(q, std::ios::binary | std::ios::trunc);
      out.write(damaged.data(), static_cast<std::streamsize>(damaged.size()));
    }
    try {
      const SpectralImage back = read_spectral_exr(q);
      ASSERT_EQ(back.lights.size(), 2u);
      EXPECT_EQ(back.lights[0].data, img.lights[0].data) << "byte " << at << " changed pixels silently";
      EXPECT_EQ(back.lights[1].data, img.lights[1].data) << "byte " << at << " changed pixels silently";
      ++unchanged;
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(q.string()), std::string::npos) << what;
      (what.find("prizma:checksum") != std::string::npos ? refused_by_checksum : refused_otherwise)++;
    }
  }
  // The checksum is what catches most of them (PIZ decodes most damage into other numbers).
  EXPECT_GT(refused_by_checksum, 0);
  std::cout << "damaged bytes: " << refused_by_checksum << " refused by the checksum, " << refused_otherwise
            << " by OpenEXR, " << unchanged << " unchanged\n";
}

TEST_F(SpectralExr, RefusesUnknownChecksumKind) {
  const SpectralImage img = make_image(2, 2, BinLayout::linear(400, 700, 3), {"a"});
  const fs::path p = file("sum.exr");
  write_spectral_exr(p, img);
  const fs::path out = rewrite_header(p, file("sum-rewritten.exr"), [](Imf::Header& h) {
    h.insert("prizma:checksum", Imf::StringAttribute("crc32:1234"));
  });
  const std::string err = read_error(out);
  EXPECT_NE(err.find("not of a known kind"), std::string::npos) << err;
}

// Checksum v2 covers the top-level T layer (the sum of the lights); v1 files (older writers) still
// read; a file re-encoded by another tool is refused naming the signs; verify_checksum off reads it.
TEST_F(SpectralExr, ChecksumCoversTheTopLevelSumLayer) {
  const SpectralImage img = make_image(4, 3, BinLayout::linear(400, 700, 3), {"key", "fill"});
  const fs::path p = file("two.exr");
  write_spectral_exr(p, img);
  // The checksum of the lights alone (v1) differs from the stored one: the sum is covered.
  SpectralImage key = img, fill = img;
  key.lights.erase(key.lights.begin() + 1);
  fill.lights.erase(fill.lights.begin());
  const std::uint64_t v1 = checksum_value(spectral_pixel_checksum(key)) + checksum_value(spectral_pixel_checksum(fill));
  Imf::InputFile in(p.c_str());
  const std::string stored = in.header().findTypedAttribute<Imf::StringAttribute>("prizma:checksum")->value();
  EXPECT_EQ(stored, spectral_pixel_checksum(img));
  EXPECT_NE(checksum_value(stored), v1);
  // One value of the sum layer changed: refused.
  const fs::path bad = rewrite_pixels(p, file("two-bad-sum.exr"), [](const std::string& name, std::vector<float>& v) {
    if (name == "T.450,000000nm") v[5] += 0.25f;
  });
  const std::string err = read_error(bad);
  // The message names the option of whichever tool reads the file, never another tool (issue 15:
  // prizma-render merge and --resume read shards too).
  EXPECT_TRUE(err.ends_with("pixel data do not match prizma:checksum (the file is damaged; --no-verify reads it anyway)"))
      << err;
  EXPECT_EQ(err.find("prizma-relight"), std::string::npos) << err;
  ExrReadOptions python;
  python.unverified_read = "prizma.read(path, verify=False)";
  EXPECT_TRUE(read_error(bad, python).ends_with("(the file is damaged; prizma.read(path, verify=False) reads it anyway)"))
      << read_error(bad, python);
  // The same file with a v1 checksum (an older writer's: lights only) is read: old files stay readable.
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(v1));
  const fs::path old = rewrite_header(p, file("two-v1.exr"), [&](Imf::Header& h) {
    h.insert("prizma:checksum", Imf::StringAttribute(std::string("fnv1a64-words:") + hex));
  });
  const SpectralImage back = read_spectral_exr(old);
  EXPECT_EQ(back.lights[0].data, img.lights[0].data);
  EXPECT_EQ(back.lights[1].data, img.lights[1].data);
  // … and a wrong v1 value is still refused.
  const fs::path old_bad = rewrite_header(p, file("two-v1-bad.exr"), [&](Imf::Header& h) {
    h.insert("prizma:checksum", Imf::StringAttribute("fnv1a64-words:0123456789abcdef"));
  });
  EXPECT_NE(read_error(old_bad).find("do not match prizma:checksum"), std::string::npos);
}

TEST_F(SpectralExr, ReencodedFileIsNamedAsSuchAndReadsWithoutVerification) {
  const SpectralImage img = make_image(16, 16, BinLayout::linear(400, 700, 4), {"key", "fill"});
  const fs::path p = file("orig.exr");
  write_spectral_exr(p, img);
  // What oiiotool --compression pxr24 does: a lossy compression (floats rounded to 24 bits), its name.
  const fs::path half_pxr24 = rewrite_header(p, file("pxr24.exr"), [](Imf::Header& h) {
    h.compression() = Imf::PXR24_COMPRESSION;
    h.insert("Software", Imf::StringAttribute("OpenImageIO 2.4.7.1 : oiiotool orig.exr --compression pxr24 -o pxr24.exr"));
  });
  const std::string err = read_error(half_pxr24);
  EXPECT_NE(err.find("pixel data do not match prizma:checksum: the file was probably re-encoded by another tool "
                     "(its compression is the lossy PXR24, Prizma writes an image this small uncompressed; it "
                     "was written by OpenImageIO 2.4.7.1)"),
            std::string::npos)
      << err;
  EXPECT_TRUE(err.ends_with("which kept the attribute but not the exact values; --no-verify reads it")) << err;
  EXPECT_EQ(err.find("prizma-relight"), std::string::npos) << err;
  ExrReadOptions no_verify;
  no_verify.verify_checksum = false;
  const SpectralImage back = read_spectral_exr(half_pxr24, no_verify);
  ASSERT_EQ(back.lights.size(), 2u);
  for (std::size_t k = 0; k < back.lights[0].data.size(); ++k) {
    ASSERT_NEAR(back.lights[0].data[k], img.lights[0].data[k], 1e-4f * img.lights[0].data[k] + 1e-6f);
  }
  // ZIP, lossless but not Prizma's: named as well.
  const fs::path zip = rewrite_pixels(
      rewrite_header(p, file("zip.exr"), [](Imf::Header& h) { h.compression() = Imf::ZIP_COMPRESSION; }),
      file("zip-edited.exr"), [](const std::string& name, std::vector<float>& v) {
        if (name == "key.T.437,500000nm") v[0] *= 0.5f;
      });
  EXPECT_NE(read_error(zip).find("(its compression is ZIP, Prizma writes an image this small uncompressed)"),
            std::string::npos)
      << read_error(zip);
}

// issue 11: a FIFO or a device given as the EXR blocked forever.
TEST_F(SpectralExr, RefusesNonRegularFiles) {
  ASSERT_EQ(::mkfifo(file("pipe.exr").c_str(), 0600), 0);
  EXPECT_NE(read_error(file("pipe.exr")).find("is a FIFO (named pipe)"), std::string::npos) << read_error(file("pipe.exr"));
  EXPECT_NE(read_error("/dev/zero").find("/dev/zero: is a character device"), std::string::npos);
  fs::create_directory(file("folder.exr"));
  EXPECT_NE(read_error(file("folder.exr")).find("is a folder, not an OpenEXR file"), std::string::npos)
      << read_error(file("folder.exr"));
}
