// The spectral EXR layout: round trips, the published single-layer layout written by plain OpenEXR
// code, and the refusals of read_spectral_exr.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <ImfChannelList.h>
#include <ImfFloatVectorAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfMatrixAttribute.h>
#include <ImfVecAttribute.h>
#include <ImfOutputFile.h>
#include <ImfPreviewImage.h>
#include <ImfStringAttribute.h>
#include <ImfStringVectorAttribute.h>
#include <ImfThreading.h>
#include <half.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "prizma/spectral/error.h"
#include "prizma/spectral/spectral_exr.h"

namespace fs = std::filesystem;
using namespace prizma::spectral;

namespace {

class SpectralExr : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    m_dir = fs::temp_directory_path() / ("prizma-test-exr-" + std::to_string(::getpid()) + "-" + info->name());
    fs::remove_all(m_dir);
    fs::create_directories(m_dir);
  }
  void TearDown() override { fs::remove_all(m_dir); }
  fs::path file(const std::string& name) const { return m_dir / name; }
  fs::path m_dir;
};

// Random transport in [0, 2), a fixed seed per light.
TransportLayer make_layer(const std::string& name, int w, int h, int bins, unsigned seed, bool variance) {
  TransportLayer l;
  l.name = name;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 2.0f);
  l.data.resize(static_cast<std::size_t>(w) * h * bins);
  for (auto& v : l.data) v = u(rng);
  if (variance) {
    l.variance.resize(l.data.size());
    for (auto& v : l.variance) v = 1e-3f * u(rng);
  }
  return l;
}

SpectralImage make_image(int w, int h, const BinLayout& bins, const std::vector<std::string>& names,
                         bool variance = false) {
  SpectralImage img;
  img.width = w;
  img.height = h;
  img.bins = bins;
  unsigned seed = 1;
  for (const auto& n : names) img.lights.push_back(make_layer(n, w, h, bins.size(), seed++, variance));
  return img;
}

std::vector<std::string> channel_names(const fs::path& p) {
  Imf::InputFile f(p.c_str());
  std::vector<std::string> out;
  for (auto it = f.header().channels().begin(); it != f.header().channels().end(); ++it) out.push_back(it.name());
  return out;
}

bool has_channel(const fs::path& p, const std::string& name) {
  Imf::InputFile f(p.c_str());
  return f.header().channels().findChannel(name) != nullptr;
}

// Writes a file of the published layout with plain OpenEXR code: one value per channel, constant over
// the image, channel names given verbatim.
void write_plain_exr(const fs::path& p, int w, int h, const std::vector<std::string>& names,
                     const std::vector<float>& values, Imf::PixelType type = Imf::FLOAT) {
  Imf::Header header(w, h);
  header.insert("spectralLayoutVersion", Imf::StringAttribute("1.0"));
  for (const auto& n : names) header.channels().insert(n, Imf::Channel(type));
  std::vector<std::vector<float>> planes(names.size());
  std::vector<std::vector<half>> half_planes(names.size());
  Imf::FrameBuffer fb;
  for (std::size_t c = 0; c < names.size(); ++c) {
    planes[c].assign(static_cast<std::size_t>(w) * h, values[c]);
    half_planes[c].assign(planes[c].size(), half(values[c]));
    char* base = type == Imf::HALF ? reinterpret_cast<char*>(half_planes[c].data())
                                   : reinterpret_cast<char*>(planes[c].data());
    const std::size_t elem = type == Imf::HALF ? sizeof(half) : sizeof(float);
    fb.insert(names[c], Imf::Slice(type, base, elem, elem * static_cast<std::size_t>(w)));
  }
  Imf::OutputFile out(p.c_str(), header);
  out.setFrameBuffer(fb);
  out.writePixels(h);
}

// Copies a float file to `out` with its header changed by `edit`; the pixels are kept as they are.
fs::path rewrite_header(const fs::path& in_path, const fs::path& out, const std::function<void(Imf::Header&)>& edit) {
  Imf::InputFile in(in_path.c_str());
  Imf::Header h = in.header();
  const Imath::Box2i dw = h.dataWindow();
  const std::size_t w = static_cast<std::size_t>(dw.max.x - dw.min.x + 1);
  const std::size_t rows = static_cast<std::size_t>(dw.max.y - dw.min.y + 1);
  std::size_t channels = 0;
  for (auto it = h.channels().begin(); it != h.channels().end(); ++it) ++channels;
  std::vector<float> buf(w * rows * channels);
  Imf::FrameBuffer fb;
  std::size_t c = 0;
  for (auto it = h.channels().begin(); it != h.channels().end(); ++it, ++c) {
    fb.insert(it.name(), Imf::Slice::Make(Imf::FLOAT, buf.data() + c, dw, channels * sizeof(float),
                                          channels * w * sizeof(float)));
  }
  in.setFrameBuffer(fb);
  in.readPixels(dw.min.y, dw.max.y);
  edit(h);
  Imf::OutputFile o(out.c_str(), h);
  o.setFrameBuffer(fb);
  o.writePixels(static_cast<int>(rows));
  return out;
}

// The little-endian int32 at `at` in `bytes`.
std::int64_t le_u32_at(const std::string& bytes, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, bytes.data() + at, sizeof v);
  return v;
}

std::string read_error(const fs::path& p, const ExrReadOptions& opts = {}) {
  try {
    read_spectral_exr(p, opts);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

}  // namespace

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

TEST_F(SpectralExr, ThreeLightsWithVarianceRoundTrip) {
  SpectralImage img = make_image(6, 4, BinLayout::linear(380, 780, 16), {"key", "fill", "rim_2"}, true);
  img.lights[1].variance.clear();  // one light without variance
  img.info.seed = std::uint64_t{1} << 40;  // beyond int32: stored as a string attribute
  const fs::path p = file("three.exr");
  write_spectral_exr(p, img);

  // Top level (sum) + 3 light layers + 2 variance layers, 16 channels each, and R, G, B.
  EXPECT_EQ(channel_names(p).size(), 6u * 16u + 3u);
  EXPECT_TRUE(has_channel(p, "key.T.392,500000nm"));
  EXPECT_TRUE(has_channel(p, "key.var.T.392,500000nm"));
  EXPECT_FALSE(has_channel(p, "fill.var.T.392,500000nm"));
  EXPECT_TRUE(has_channel(p, "T.392,500000nm"));

  const SpectralImage back = read_spectral_exr(p);
  ASSERT_EQ(back.lights.size(), 3u);
  // Order from prizma:lights (the scene's), not the file's alphabetical channel order.
  EXPECT_EQ(back.lights[0].name, "key");
  EXPECT_EQ(back.lights[1].name, "fill");
  EXPECT_EQ(back.lights[2].name, "rim_2");
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(back.lights[k].data, img.lights[k].data) << k;
    EXPECT_EQ(back.lights[k].variance, img.lights[k].variance) << k;
  }
  EXPECT_EQ(back.find_light("rim_2"), 2);
  EXPECT_EQ(back.find_light("nope"), -1);
  EXPECT_EQ(back.info.seed, std::uint64_t{1} << 40);

  // The top-level layer is the sum of the lights (what a reader of the published layout shows).
  Imf::InputFile f(p.c_str());
  std::vector<float> top(6 * 4);
  Imf::FrameBuffer fb;
  fb.insert("T.392,500000nm", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(top.data()), sizeof(float), 6 * sizeof(float)));
  f.setFrameBuffer(fb);
  f.readPixels(0, 3);
  for (int px = 0; px < 24; ++px) {
    const double sum = double(img.lights[0].data[px * 16]) + img.lights[1].data[px * 16] + img.lights[2].data[px * 16];
    EXPECT_FLOAT_EQ(top[px], static_cast<float>(sum)) << px;
  }
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

TEST_F(SpectralExr, VarianceCanBeLeftOut) {
  SpectralImage img = make_image(3, 3, BinLayout::linear(400, 700, 4), {"a"}, true);
  const fs::path p = file("novar.exr");
  ExrWriteOptions opts;
  opts.write_variance = false;
  write_spectral_exr(p, img, opts);
  EXPECT_EQ(channel_names(p).size(), 4u + 3u);  // and the preview R, G, B
  EXPECT_TRUE(read_spectral_exr(p).lights[0].variance.empty());
  write_spectral_exr(p, img);
  EXPECT_TRUE(has_channel(p, "var.T.437,500000nm"));
  EXPECT_EQ(read_spectral_exr(p).lights[0].variance, img.lights[0].variance);
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

TEST_F(SpectralExr, ReadsPublishedSingleLayerLayoutWithMidpointEdges) {
  // Plain OpenEXR file, no prizma: attributes; wavelengths written in several legal spellings:
  // 500 nm, 5,5E2 nm = 550 nm, 0,6 µm = 600 nm, 650 nm as frequency c/λ in Hz. Plus an RGB preview
  // that must be ignored.
  const double hz650 = 299792458.0 / 650e-9;
  char hz_name[64];
  std::snprintf(hz_name, sizeof hz_name, "T.%.12eHz", hz650);
  std::string hz = hz_name;
  std::replace(hz.begin() + 2, hz.end(), '.', ',');
  const std::vector<std::string> names = {"T.500nm", "T.5,5E2nm", "T.0,6um", hz, "R", "G", "B"};
  const std::vector<float> values = {0.1f, 0.2f, 0.3f, 0.4f, 9.0f, 9.0f, 9.0f};
  const fs::path p = file("plain.exr");
  write_plain_exr(p, 3, 2, names, values);

  const SpectralImage img = read_spectral_exr(p);
  EXPECT_FALSE(img.info.is_prizma);
  ASSERT_EQ(img.bins.size(), 4);
  // Centres 500, 550, 600, 650: edges at midpoints, first and last mirrored.
  const std::vector<double> expected = {475, 525, 575, 625, 675};
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(img.bins.edges_nm()[i], expected[i], 1e-6) << i;
  ASSERT_EQ(img.lights.size(), 1u);
  EXPECT_EQ(img.lights[0].name, "default");
  ASSERT_EQ(img.lights[0].data.size(), 3u * 2u * 4u);
  for (int px = 0; px < 6; ++px) {
    for (int i = 0; i < 4; ++i) EXPECT_EQ(img.lights[0].data[px * 4 + i], values[i]) << px << " " << i;
  }
}

// issue 25 item 13: the reference writer's reflective file sampled at 400, 500, 600, 700 nm (no
// prizma:binEdgesNm) infers a first edge of 350 nm, below the colour matching tables: clamped to
// 360 nm and noted (prizma-relight -v prints it); a channel itself outside the tables is refused.
TEST_F(SpectralExr, InferredOuterEdgesAreClampedToTheTablesAndNoted) {
  const fs::path p = file("ref400.exr");
  write_plain_exr(p, 2, 2, {"T.400nm", "T.500nm", "T.600nm", "T.700nm"}, {0.1f, 0.2f, 0.3f, 0.4f});
  const SpectralImage img = read_spectral_exr(p);
  const std::vector<double> edges = {360, 450, 550, 650, 750};  // midpoints: exact up to rounding
  ASSERT_EQ(img.bins.edges_nm().size(), edges.size());
  for (std::size_t i = 0; i < edges.size(); ++i) EXPECT_NEAR(img.bins.edges_nm()[i], edges[i], 1e-9) << i;
  ASSERT_EQ(img.info.notes.size(), 1u);
  EXPECT_NE(img.info.notes[0].find("inferred first bin edge 350 nm is outside the colour matching tables (360–830 nm): "
                                   "clamped to 360 nm"), std::string::npos) << img.info.notes[0];
  // Both ends: 370 and 820 nm mirror to 320 and 870 nm.
  const fs::path wide = file("wide_ends.exr");
  write_plain_exr(wide, 1, 1, {"T.370nm", "T.595nm", "T.820nm"}, {1, 1, 1});
  const SpectralImage w = read_spectral_exr(wide);
  EXPECT_EQ(w.bins.min_nm(), 360.0);
  EXPECT_EQ(w.bins.max_nm(), 830.0);
  EXPECT_EQ(w.info.notes.size(), 2u);
  // A sample at 350 nm cannot be given a bin inside the tables.
  const fs::path outside = file("uv.exr");
  write_plain_exr(outside, 1, 1, {"T.350nm", "T.450nm"}, {1, 1});
  EXPECT_NE(read_error(outside).find("bin edges:"), std::string::npos) << read_error(outside);
}

TEST_F(SpectralExr, ReadsNonUniformPublishedLayoutSortedByWavelength) {
  // Alphabetical channel order ("T.1000nm" < "T.450nm"... not here, but "T.0,5um" < "T.450nm") differs
  // from wavelength order; half pixels are converted.
  const fs::path p = file("sorted.exr");
  write_plain_exr(p, 2, 2, {"T.450nm", "T.0,5um", "T.400nm", "T.600nm"}, {0.45f, 0.5f, 0.4f, 0.6f}, Imf::HALF);
  const SpectralImage img = read_spectral_exr(p);
  ASSERT_EQ(img.bins.size(), 4);
  const std::vector<double> expected = {375, 425, 475, 550, 650};
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(img.bins.edges_nm()[i], expected[i], 1e-9) << i;
  EXPECT_NEAR(img.lights[0].data[0], 0.4f, 1e-3);
  EXPECT_NEAR(img.lights[0].data[1], 0.45f, 1e-3);
  EXPECT_NEAR(img.lights[0].data[2], 0.5f, 1e-3);
  EXPECT_NEAR(img.lights[0].data[3], 0.6f, 1e-3);
}

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
std::uint64_t checksum_value(const std::string& checksum) {
  return std::stoull(checksum.substr(checksum.rfind(':') + 1), nullptr, 16);
}

// Copies an EXR, letting `edit` change any channel's values (read and written as float).
fs::path rewrite_pixels(const fs::path& in_path, const fs::path& out,
                        const std::function<void(const std::string& channel, std::vector<float>& values)>& edit) {
  Imf::InputFile in(in_path.c_str());
  const Imf::Header h = in.header();
  const Imath::Box2i dw = h.dataWindow();
  const std::size_t pixels = static_cast<std::size_t>(dw.max.x - dw.min.x + 1) * (dw.max.y - dw.min.y + 1);
  std::map<std::string, std::vector<float>> values;
  Imf::FrameBuffer fb;
  for (auto it = h.channels().begin(); it != h.channels().end(); ++it) {
    auto& v = values[it.name()];
    v.resize(pixels);
    fb.insert(it.name(), Imf::Slice::Make(Imf::FLOAT, v.data(), dw, sizeof(float),
                                          sizeof(float) * static_cast<std::size_t>(dw.max.x - dw.min.x + 1)));
  }
  in.setFrameBuffer(fb);
  in.readPixels(dw.min.y, dw.max.y);
  for (auto& [name, v] : values) edit(name, v);
  Imf::OutputFile o(out.c_str(), h);
  o.setFrameBuffer(fb);
  o.writePixels(dw.max.y - dw.min.y + 1);
  return out;
}

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

TEST_F(SpectralExr, WritesTheDefaultRelightAsLinearSrgbPreview) {
  // Light "a" at D65 on a perfect white (T = 1): linear sRGB (1, 1, 1) (D65 is sRGB's white, Y = 1);
  // light "b" recorded as off adds nothing however bright its transport.
  SpectralImage img = make_image(3, 2, BinLayout::linear(380, 780, 40), {"a", "b"});
  std::fill(img.lights[0].data.begin(), img.lights[0].data.end(), 1.0f);
  std::fill(img.lights[1].data.begin(), img.lights[1].data.end(), 5.0f);
  img.info.light_records = prizma::spectral::parse_light_records(R"([{"name":"a","spectrum":"D65"},{"name":"b","spectrum":"off"}])", "test");
  const fs::path p = file("preview.exr");
  write_spectral_exr(p, img);
  {
    Imf::InputFile in(p.c_str());
    ASSERT_NE(in.header().channels().findChannel("R"), nullptr);
    std::vector<float> rgb(3 * 6);
    Imf::FrameBuffer fb;
    const Imath::Box2i dw = in.header().dataWindow();
    for (std::size_t c = 0; c < 3; ++c)
      fb.insert(c == 0 ? "R" : c == 1 ? "G" : "B",
                Imf::Slice::Make(Imf::FLOAT, rgb.data() + c, dw, 3 * sizeof(float), 9 * sizeof(float)));
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    for (const float v : rgb) EXPECT_NEAR(v, 1.0f, 2e-3f);
  }
  const SpectralImage back = read_spectral_exr(p);  // the preview is no light and outside the checksum
  ASSERT_EQ(back.lights.size(), 2u);
  EXPECT_EQ(back.lights[0].data, img.lights[0].data);
  ExrWriteOptions no_preview;
  no_preview.write_preview = false;
  write_spectral_exr(file("bare.exr"), img, no_preview);
  Imf::InputFile bare(file("bare.exr").c_str());
  EXPECT_EQ(bare.header().channels().findChannel("R"), nullptr);
}

TEST_F(SpectralExr, RefusesEmissiveOnly) {
  const fs::path p = file("emissive.exr");
  write_plain_exr(p, 2, 2, {"S0.500nm", "S0.600nm"}, {1.0f, 2.0f});
  const std::string err = read_error(p);
  EXPECT_NE(err.find(p.string()), std::string::npos) << err;
  EXPECT_NE(err.find("emissive"), std::string::npos) << err;
}

TEST_F(SpectralExr, RefusesNoSpectralChannels) {
  const fs::path p = file("rgb.exr");
  write_plain_exr(p, 2, 2, {"R", "G", "B"}, {1.0f, 2.0f, 3.0f});
  const std::string err = read_error(p);
  EXPECT_NE(err.find("no spectral channels"), std::string::npos) << err;
}

TEST_F(SpectralExr, RefusesSingleChannelWithoutEdges) {
  const fs::path p = file("single.exr");
  write_plain_exr(p, 2, 2, {"T.550nm"}, {1.0f});
  EXPECT_NE(read_error(p).find("bin width"), std::string::npos);
}

TEST_F(SpectralExr, RefusesInconsistentEdges) {
  const SpectralImage img = make_image(2, 2, BinLayout::linear(400, 700, 3), {"a"});
  const fs::path p = file("edges.exr");
  write_spectral_exr(p, img);
  auto rewrite_edges = [&](const std::vector<float>& edges) {
    return rewrite_header(p, file("edges-rewritten.exr"), [&](Imf::Header& h) {
      h.insert("prizma:binEdgesNm", Imf::FloatVectorAttribute(edges));
      h.erase("prizma:binEdgesNmExact");
    });
  };
  // Wrong count.
  std::string err = read_error(rewrite_edges({400, 500, 600}));
  EXPECT_NE(err.find("3 edges for 3 spectral channels"), std::string::npos) << err;
  // Centre 450 outside its bin [400, 440].
  err = read_error(rewrite_edges({400, 440, 600, 650}));
  EXPECT_NE(err.find("not inside its bin"), std::string::npos) << err;
  // Consistent but different edges are accepted as written.
  const SpectralImage ok = read_spectral_exr(rewrite_edges({420, 480, 620, 680}));
  EXPECT_EQ(ok.bins.edges_nm(), (std::vector<double>{420, 480, 620, 680}));
}

TEST_F(SpectralExr, RefusesLightLayersWithDifferentChannels) {
  const fs::path p = file("mismatch.exr");
  write_plain_exr(p, 2, 2, {"a.T.500nm", "a.T.600nm", "b.T.500nm", "b.T.650nm"}, {1, 2, 3, 4});
  const std::string err = read_error(p);
  EXPECT_NE(err.find("share their channels"), std::string::npos) << err;
}

TEST_F(SpectralExr, RefusesNaNNamingTheLayer) {
  const fs::path p = file("nan.exr");
  write_plain_exr(p, 2, 2, {"key.T.500nm", "key.T.600nm", "fill.T.500nm", "fill.T.600nm"},
                  {1, 2, std::numeric_limits<float>::quiet_NaN(), 4});
  const std::string err = read_error(p);
  EXPECT_NE(err.find("NaN"), std::string::npos) << err;
  EXPECT_NE(err.find("fill"), std::string::npos) << err;
}

TEST_F(SpectralExr, ReadsPlainMultiLayerFileAsLights) {
  // Layers without prizma:lights come back in the file's (alphabetical) order.
  const fs::path p = file("layers.exr");
  write_plain_exr(p, 1, 1, {"key.T.500nm", "key.T.600nm", "fill.T.500nm", "fill.T.600nm"}, {1, 2, 3, 4});
  const SpectralImage img = read_spectral_exr(p);
  ASSERT_EQ(img.lights.size(), 2u);
  EXPECT_EQ(img.lights[0].name, "fill");
  EXPECT_EQ(img.lights[1].name, "key");
  EXPECT_EQ(img.lights[1].data, (std::vector<float>{1, 2}));
}

TEST_F(SpectralExr, RefusesInvalidLightsJson) {
  SpectralImage img = make_image(1, 1, BinLayout::linear(400, 700, 2), {"a"});
  write_spectral_exr(file("ok.exr"), img);
  const fs::path p = rewrite_header(file("ok.exr"), file("json.exr"), [](Imf::Header& h) {
    h.insert("prizma:lights", Imf::StringAttribute("[{not json"));
  });
  const std::string err = read_error(p);
  EXPECT_NE(err.find("prizma:lights: is not valid JSON"), std::string::npos) << err;
}

// One light record, one reader and writer (light_record.h): the writer refuses records its reader would.
TEST_F(SpectralExr, WriterRefusesLightRecordsThatDoNotDescribeTheLayers) {
  SpectralImage img = make_image(1, 1, BinLayout::linear(400, 700, 2), {"key", "fill"});
  img.info.light_records = light_records_for({"key", "back"});
  const fs::path p = file("records.exr");
  try {
    write_spectral_exr(p, img);
    FAIL() << "written";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), p.string() + ": prizma:lights announces light \"back\" but the file has no layer "
                                                  "for it (layers: key, fill)");
  }
  EXPECT_FALSE(fs::exists(p));
}

TEST_F(SpectralExr, ReadsDataWindowNotAtOrigin) {
  // Data window (10, 20)–(12, 21): 3×2 pixels; values encode (x, y, channel).
  const fs::path p = file("window.exr");
  const Imath::Box2i dw({10, 20}, {12, 21});
  Imf::Header header(Imath::Box2i({0, 0}, {31, 31}), dw);
  const std::vector<std::string> names = {"T.500nm", "T.600nm"};
  std::vector<float> px(3 * 2 * 2);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x)
      for (int c = 0; c < 2; ++c) px[(y * 3 + x) * 2 + c] = static_cast<float>(100 * y + 10 * x + c);
  Imf::FrameBuffer fb;
  for (int c = 0; c < 2; ++c) {
    header.channels().insert(names[c], Imf::Channel(Imf::FLOAT));
    fb.insert(names[c], Imf::Slice::Make(Imf::FLOAT, px.data() + c, dw, 2 * sizeof(float), 6 * sizeof(float)));
  }
  {
    Imf::OutputFile out(p.c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(2);
  }
  const SpectralImage img = read_spectral_exr(p);
  EXPECT_EQ(img.width, 3);
  EXPECT_EQ(img.height, 2);
  EXPECT_EQ(img.lights[0].data, px);
}

// issue 11: oiiotool rewrites a float array of 2, 3, 9 or 16 values as v2f, v3f, m33f or m44f;
// the reader ignored those and fell back to midpoint edges (~10× off for non-uniform bins).
TEST_F(SpectralExr, ReadsBinEdgesInEveryNumericFormOpenExrHolds) {
  auto edges_of = [](int n) {
    std::vector<double> e;
    for (int i = 0; i <= n; ++i) e.push_back(400.0 + 300.0 * (i * i) / (n * n) + 3.0 * i);  // non-uniform
    return e;
  };
  struct Form {
    int bins;
    std::function<void(Imf::Header&, const std::vector<float>&)> put;
  };
  const std::vector<Form> forms = {
      {1, [](Imf::Header& h, const std::vector<float>& e) { h.insert("prizma:binEdgesNm", Imf::V2fAttribute({e[0], e[1]})); }},
      {2, [](Imf::Header& h, const std::vector<float>& e) {
         h.insert("prizma:binEdgesNm", Imf::V3fAttribute({e[0], e[1], e[2]}));
       }},
      {2, [](Imf::Header& h, const std::vector<float>& e) {
         h.insert("prizma:binEdgesNm", Imf::V3dAttribute({e[0], e[1], e[2]}));
       }},
      {8, [](Imf::Header& h, const std::vector<float>& e) {
         h.insert("prizma:binEdgesNm", Imf::M33fAttribute(Imath::M33f(e[0], e[1], e[2], e[3], e[4], e[5], e[6], e[7], e[8])));
       }},
      {15, [](Imf::Header& h, const std::vector<float>& e) {
         Imath::M44f m;
         for (int i = 0; i < 16; ++i) m[i / 4][i % 4] = e[static_cast<std::size_t>(i)];
         h.insert("prizma:binEdgesNm", Imf::M44fAttribute(m));
       }},
  };
  for (const Form& form : forms) {
    SCOPED_TRACE(form.bins);
    const BinLayout bins = BinLayout::from_edges(edges_of(form.bins));
    const fs::path p = file("edges.exr");
    write_spectral_exr(p, make_image(2, 2, bins, {"a"}));
    std::vector<float> fe(bins.edges_nm().begin(), bins.edges_nm().end());
    const fs::path q = rewrite_header(p, file("copied.exr"), [&](Imf::Header& h) {
      h.erase("prizma:binEdgesNm");
      form.put(h, fe);
    });
    const SpectralImage img = read_spectral_exr(q);
    ASSERT_EQ(img.bins.size(), form.bins);
    for (int i = 0; i <= form.bins; ++i) EXPECT_NEAR(img.bins.edges_nm()[i], bins.edges_nm()[i], 1e-12) << i;
  }
}

// issue 11: edges whose bins do not have the channels' wavelengths as centres were accepted.
TEST_F(SpectralExr, RefusesRecordedEdgesThatDisagreeWithTheChannels) {
  const fs::path p = file("edges.exr");
  write_spectral_exr(p, make_image(2, 2, BinLayout::linear(400, 700, 3), {"a"}));  // centres 450, 550, 650
  const fs::path q = rewrite_header(p, file("moved.exr"), [&](Imf::Header& h) {
    h.insert("prizma:binEdgesNm", Imf::FloatVectorAttribute({400, 470, 560, 700}));
    h.erase("prizma:binEdgesNmExact");
  });
  std::string err = read_error(q);
  EXPECT_NE(err.find("is not the centre 435 nm of its bin [400, 470]"), std::string::npos) << err;
  const fs::path r = rewrite_header(p, file("string.exr"), [&](Imf::Header& h) {
    h.erase("prizma:binEdgesNm");
    h.insert("prizma:binEdgesNm", Imf::StringAttribute("400 500 600 700"));
  });
  err = read_error(r);
  EXPECT_NE(err.find("prizma:binEdgesNm has type string"), std::string::npos) << err;
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

// issue 11: a deeply nested prizma:lights record is refused (nlohmann recurses on such values).
TEST_F(SpectralExr, RefusesDeeplyNestedLightsJson) {
  SpectralImage img = make_image(1, 1, BinLayout::linear(400, 700, 2), {"a"});
  write_spectral_exr(file("ok.exr"), img);
  const fs::path p = rewrite_header(file("ok.exr"), file("deep.exr"), [](Imf::Header& h) {
    h.insert("prizma:lights", Imf::StringAttribute(std::string(70000, '[') + std::string(70000, ']')));
  });
  const std::string err = read_error(p);
  EXPECT_NE(err.find("prizma:lights: JSON nested deeper than"), std::string::npos) << err;
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
