// The spectral EXR writer: round trips of one light, bit exact in float and within half precision,
// the bytes independent of the thread count, the compression threshold, the seed attribute, and the
// writer's refusals.
#include "spectral_exr_test_support.h"

using namespace prizma::spectral;
using namespace prizma::spectral::exr_test;

TEST(SpectralChannelName, SixDecimalsWithComma) {
  EXPECT_EQ(spectral_channel_name(550.0), "T.550,000000nm");
  EXPECT_EQ(spectral_channel_name(392.5), "T.392,500000nm");
  EXPECT_EQ(spectral_channel_name(412.3456789), "T.412,345679nm");
  EXPECT_EQ(spectral_channel_name(550.0, "key"), "key.T.550,000000nm");
  EXPECT_EQ(spectral_channel_name(550.0, "key.var"), "key.var.T.550,000000nm");
}

TEST_F(SpectralExr, OneLightRoundTripIsBitExact) {
  SpectralImage img = make_image(7, 5, BinLayout::linear(400, 700, 12), {"sun"});
  img.info.samples = 256;
  img.info.seed = 42;
  img.info.sample_range = "0:256";
  img.info.scene_hash = "abc123";
  img.info.version = "test-version";
  img.info.wavelength_sampling = "spectral-tracking";
  img.info.light_records = prizma::spectral::parse_light_records(R"([{"name":"sun","direction":[0,0,1],"angularSizeDeg":0.5,"spectrum":"D65"}])", "test");
  const fs::path p = file("one.exr");
  write_spectral_exr(p, img);

  // The file: top-level T channels only (and the R, G, B preview), no per-light layer, the layout
  // version attribute.
  const auto names = channel_names(p);
  EXPECT_EQ(names.size(), 12u + 3u);
  EXPECT_TRUE(has_channel(p, "T.412,500000nm"));
  EXPECT_FALSE(has_channel(p, "sun.T.412,500000nm"));
  {
    Imf::InputFile f(p.c_str());
    const auto* v = f.header().findTypedAttribute<Imf::StringAttribute>("spectralLayoutVersion");
    ASSERT_NE(v, nullptr);
    EXPECT_EQ(v->value(), "1.0");
    const auto* e = f.header().findTypedAttribute<Imf::FloatVectorAttribute>("prizma:binEdgesNm");
    ASSERT_NE(e, nullptr);
    ASSERT_EQ(e->value().size(), 13u);
    EXPECT_EQ(e->value().front(), 400.0f);
    EXPECT_EQ(e->value().back(), 700.0f);
    EXPECT_EQ(f.header().channels().begin().channel().type, Imf::FLOAT);
  }

  const SpectralImage back = read_spectral_exr(p);
  EXPECT_EQ(back.width, 7);
  EXPECT_EQ(back.height, 5);
  EXPECT_EQ(back.bins, img.bins);
  ASSERT_EQ(back.lights.size(), 1u);
  EXPECT_EQ(back.lights[0].name, "sun");  // from prizma:lights
  EXPECT_EQ(back.lights[0].data, img.lights[0].data);
  EXPECT_TRUE(back.lights[0].variance.empty());
  EXPECT_TRUE(back.info.is_prizma);
  EXPECT_EQ(back.info.samples, 256);
  EXPECT_EQ(back.info.seed, 42);
  EXPECT_EQ(back.info.sample_range, "0:256");
  EXPECT_EQ(back.info.scene_hash, "abc123");
  EXPECT_EQ(back.info.version, "test-version");
  EXPECT_EQ(back.info.wavelength_sampling, "spectral-tracking");
  EXPECT_EQ(back.info.light_records, img.info.light_records);
}

// ExrWriteOptions::threads: encoded in the calling thread (1), or with 2 or all of OpenEXR's pool in
// flight, the file is the same byte for byte (several 32-line PIZ chunks, half and float: 43 channels
// of 37×400 pixels, 2.5 and 1.3 MB, above the 1 MiB that is written uncompressed).
TEST_F(SpectralExr, ThreadCountDoesNotChangeAByte) {
  const SpectralImage img = make_image(37, 400, BinLayout::linear(400, 700, 8), {"key", "fill"}, true);
  auto bytes = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  for (const ExrPixelType type : {ExrPixelType::Float, ExrPixelType::Half}) {
    std::vector<std::string> files;
    for (int threads : {1, 2, 0}) {
      ExrWriteOptions wo;
      wo.pixel_type = type;
      wo.threads = threads;
      const fs::path p = file("threads_" + std::to_string(threads) + ".exr");
      write_spectral_exr(p, img, wo);
      files.push_back(bytes(p));
    }
    ASSERT_GT(files[0].size(), 100000u);
    EXPECT_EQ(Imf::InputFile(file("threads_1.exr").c_str()).header().compression(), Imf::PIZ_COMPRESSION);
    EXPECT_TRUE(files[0] == files[1]);
    EXPECT_TRUE(files[0] == files[2]);
  }
}

TEST_F(SpectralExr, NonUniformBinsRoundTripExactly) {
  const BinLayout bins = BinLayout::exponential(380, 780, 10, 1.7);
  SpectralImage img = make_image(4, 3, bins, {"a", "b"});
  const fs::path p = file("exp.exr");
  write_spectral_exr(p, img);
  const SpectralImage back = read_spectral_exr(p);
  EXPECT_EQ(back.bins, bins);  // exact, through prizma:binEdgesNmExact
  EXPECT_TRUE(has_channel(p, spectral_channel_name(bins.centre_nm(3), "b")));
  EXPECT_EQ(back.lights[1].data, img.lights[1].data);
}

TEST_F(SpectralExr, HalfRoundTripWithinHalfPrecision) {
  SpectralImage img = make_image(5, 5, BinLayout::linear(400, 700, 6), {"a"});
  const fs::path p = file("half.exr");
  ExrWriteOptions opts;
  opts.pixel_type = ExrPixelType::Half;
  write_spectral_exr(p, img, opts);
  {
    Imf::InputFile f(p.c_str());
    EXPECT_EQ(f.header().channels().begin().channel().type, Imf::HALF);
  }
  const SpectralImage back = read_spectral_exr(p);
  ASSERT_EQ(back.lights[0].data.size(), img.lights[0].data.size());
  for (std::size_t k = 0; k < img.lights[0].data.size(); ++k) {
    // half has an 11-bit significand: relative rounding error ≤ 2^-11.
    EXPECT_NEAR(back.lights[0].data[k], img.lights[0].data[k], img.lights[0].data[k] * (1.0 / 2048) + 1e-7) << k;
  }
}

TEST_F(SpectralExr, HalfRefusesValuesBeyondRangeUnlessClamped) {
  SpectralImage img = make_image(2, 2, BinLayout::linear(400, 700, 3), {"a"});
  img.lights[0].data[5] = 70000.0f;
  const fs::path p = file("big.exr");
  ExrWriteOptions opts;
  opts.pixel_type = ExrPixelType::Half;
  try {
    write_spectral_exr(p, img, opts);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("65504"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(p));

  opts.clamp_half = true;
  ::testing::internal::CaptureStderr();
  write_spectral_exr(p, img, opts);
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("warning"), std::string::npos) << err;
  EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
  const SpectralImage back = read_spectral_exr(p);
  EXPECT_EQ(back.lights[0].data[5], 65504.0f);

  // Float keeps the value.
  write_spectral_exr(p, img);
  EXPECT_EQ(read_spectral_exr(p).lights[0].data[5], 70000.0f);
}

TEST_F(SpectralExr, WriterRefusesNaNAndBadNames) {
  SpectralImage img = make_image(2, 2, BinLayout::linear(400, 700, 3), {"a", "b"});
  const fs::path p = file("bad.exr");
  img.lights[1].data[4] = std::numeric_limits<float>::quiet_NaN();
  try {
    write_spectral_exr(p, img);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("NaN"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("\"b\""), std::string::npos) << e.what();
  }
  img.lights[1].data[4] = 0.5f;
  img.lights[1].name = "bad name";
  EXPECT_THROW(write_spectral_exr(p, img), InputError);
  img.lights[1].name = "a";
  EXPECT_THROW(write_spectral_exr(p, img), InputError);  // duplicate
  img.lights[1].name = "b";
  img.lights[1].data.pop_back();
  EXPECT_THROW(write_spectral_exr(p, img), InputError);  // wrong size
  EXPECT_FALSE(fs::exists(p));
}

TEST_F(SpectralExr, WriterKeepsExistingFileOnFailure) {
  SpectralImage good = make_image(2, 2, BinLayout::linear(400, 700, 3), {"a"});
  const fs::path p = file("keep.exr");
  write_spectral_exr(p, good);
  SpectralImage bad = good;
  bad.lights[0].data[0] = std::numeric_limits<float>::infinity();
  EXPECT_THROW(write_spectral_exr(p, bad), InputError);
  EXPECT_EQ(read_spectral_exr(p).lights[0].data, good.lights[0].data);
  EXPECT_THROW(write_spectral_exr(file("no/such/folder/x.exr"), good), RuntimeError);
}

// prizma:seed holds every 64-bit seed: 2^64 − 1 is a string attribute "18446744073709551615" (it was
// the int −1 before), and the files that stored seeds from 2^63 on as negative numbers read back the
// seed they were rendered with (docs/spectral-exr.md).
TEST_F(SpectralExr, SeedKeepsAllSixtyFourBits) {
  SpectralImage img = make_image(2, 2, BinLayout::linear(400, 700, 3), {"a"});
  img.info.seed = std::numeric_limits<std::uint64_t>::max();
  const fs::path p = file("seed.exr");
  write_spectral_exr(p, img);
  EXPECT_EQ(read_spectral_exr(p).info.seed, std::numeric_limits<std::uint64_t>::max());
  {
    Imf::InputFile f(p.c_str());
    const auto* attr = f.header().findTypedAttribute<Imf::StringAttribute>("prizma:seed");
    ASSERT_NE(attr, nullptr);
    EXPECT_EQ(attr->value(), "18446744073709551615");
  }
  const fs::path old_int = rewrite_header(p, file("seed-old-int.exr"), [](Imf::Header& h) {
    h.erase("prizma:seed");
    h.insert("prizma:seed", Imf::IntAttribute(-1));
  });
  EXPECT_EQ(read_spectral_exr(old_int).info.seed, std::numeric_limits<std::uint64_t>::max());
  const fs::path old_string = rewrite_header(p, file("seed-old-string.exr"), [](Imf::Header& h) {
    h.insert("prizma:seed", Imf::StringAttribute("-9223372036854775807"));  // 2^63 + 1
  });
  EXPECT_EQ(read_spectral_exr(old_string).info.seed, (std::uint64_t{1} << 63) + 1);
  const fs::path bad = rewrite_header(p, file("seed-bad.exr"), [](Imf::Header& h) {
    h.insert("prizma:seed", Imf::StringAttribute("18446744073709551616"));  // 2^64
  });
  EXPECT_NE(read_error(bad).find("prizma:seed: \"18446744073709551616\" is not a 64-bit seed"), std::string::npos)
      << read_error(bad);
}

// prizma:misLaneGroups: written when set (spectral MIS's paths per sample), read back; absent is 0;
// a value no render writes is refused with the attribute's name, by the reader and by the writer.
TEST_F(SpectralExr, MisLaneGroupsRoundTripAndBadValuesAreRefused) {
  SpectralImage img = make_image(2, 2, BinLayout::linear(400, 700, 3), {"a"});
  const fs::path none = file("groups-none.exr");
  write_spectral_exr(none, img);
  EXPECT_EQ(read_spectral_exr(none).info.mis_lane_groups, 0);
  img.info.mis_lane_groups = 3;
  const fs::path p = file("groups.exr");
  write_spectral_exr(p, img);
  EXPECT_EQ(read_spectral_exr(p).info.mis_lane_groups, 3);
  for (const int bad : {-1, 1025}) {
    const fs::path q = rewrite_header(p, file("groups-bad.exr"), [bad](Imf::Header& h) {
      h.insert("prizma:misLaneGroups", Imf::IntAttribute(bad));
    });
    EXPECT_NE(read_error(q).find("prizma:misLaneGroups: " + std::to_string(bad) + " is not a lane group count"),
              std::string::npos)
        << read_error(q);
    img.info.mis_lane_groups = bad;
    try {
      write_spectral_exr(file("groups-bad-written.exr"), img);
      ADD_FAILURE() << "wrote prizma:misLaneGroups " << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("is not a lane group count"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(file("groups-bad-written.exr")));
  }
}

// Compression (docs/spectral-exr.md): at most 1 MiB of pixel data (all channels as stored) is
// written uncompressed, in the calling thread (OpenEXR's pool is not started for it); one byte more,
// PIZ. Both read back exactly. One light, 13 bins and R, G, B: 16 floats, 64 bytes per pixel.
TEST_F(SpectralExr, SmallImagesAreWrittenUncompressedLargerOnesWithPiz) {
  const BinLayout bins = BinLayout::linear(400, 700, 13);
  const int pool_before = Imf::globalThreadCount();
  const SpectralImage small = make_image(128, 128, bins, {"a"});  // 128·128·64 bytes = 1 MiB exactly
  const fs::path ps = file("small.exr");
  write_spectral_exr(ps, small);
  EXPECT_EQ(Imf::globalThreadCount(), pool_before);
  const SpectralImage large = make_image(128, 129, bins, {"a"});
  const fs::path pl = file("large.exr");
  write_spectral_exr(pl, large);
  EXPECT_EQ(Imf::InputFile(ps.c_str()).header().compression(), Imf::NO_COMPRESSION);
  EXPECT_EQ(Imf::InputFile(pl.c_str()).header().compression(), Imf::PIZ_COMPRESSION);
  EXPECT_EQ(read_spectral_exr(ps).lights[0].data, small.lights[0].data);
  EXPECT_EQ(read_spectral_exr(pl).lights[0].data, large.lights[0].data);
  // A half file counts its bytes as stored: 128×256 pixels of 16 halves, 1 MiB, uncompressed.
  ExrWriteOptions half_opts;
  half_opts.pixel_type = ExrPixelType::Half;
  const fs::path ph = file("small_half.exr");
  write_spectral_exr(ph, make_image(128, 256, bins, {"a"}), half_opts);
  EXPECT_EQ(Imf::InputFile(ph.c_str()).header().compression(), Imf::NO_COMPRESSION);
  // A damaged re-encoding of the large file names what Prizma writes at its size: PIZ, so an
  // uncompressed copy is a sign too (for the small file it is not: ReencodedFileIsNamed… above).
  for (const auto& [compression, sign] : {std::pair{Imf::ZIP_COMPRESSION, "(its compression is ZIP, Prizma writes PIZ)"},
                                          std::pair{Imf::NO_COMPRESSION, "(its compression is none, Prizma writes PIZ)"}}) {
    const fs::path copy = rewrite_pixels(
        rewrite_header(pl, file("large-copy.exr"), [c = compression](Imf::Header& h) { h.compression() = c; }),
        file("large-edited.exr"), [](const std::string& name, std::vector<float>& v) {
          if (name == "T.411,538462nm") v[0] *= 0.5f;
        });
    EXPECT_NE(read_error(copy).find(sign), std::string::npos) << read_error(copy);
  }
}
