// Spectral-basis coefficients in the spectral EXR (docs/spectral-exr.md, "Spectral-basis
// coefficients"): round trip with and without the bins, the checksum covering them, and what the
// reader refuses (a damaged coefficient channel, a missing basis, a compact file for a tool that
// needs the bins).
#include <ImfChannelList.h>
#include <ImfFloatVectorAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <gtest/gtest.h>
#include <half.h>

#include <cmath>
#include <filesystem>
#include <map>
#include <random>
#include <string>

#include "prizma/spectral/error.h"
#include "prizma/spectral/spectral_basis.h"
#include "prizma/spectral/spectral_exr.h"
#include "scratch_files.h"

namespace prizma::spectral {
namespace {

namespace fs = std::filesystem;

class CoefficientsExr : public ::testing::Test {
 protected:
  void SetUp() override {
    m_dir = test::scratch_dir("coef", ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  void TearDown() override { fs::remove_all(m_dir); }
  fs::path file(const std::string& name) const { return m_dir / name; }
  fs::path m_dir;
};

// A small image of smooth spectra, every layer with a k-term basis and its coefficients.
SpectralImage image_with_coefficients(int lights, int k) {
  SpectralImage img;
  img.width = 12;
  img.height = 7;
  img.bins = BinLayout::linear(400.0, 700.0, 8);
  const int n = img.bins.size();
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const char* names[] = {"key", "fill", "rim"};
  for (int l = 0; l < lights; ++l) {
    TransportLayer layer;
    layer.name = names[l];
    layer.data.resize(img.pixel_count() * static_cast<std::size_t>(n));
    for (float& v : layer.data) v = u(rng);
    const SpectralBasis basis = spectral_basis(layer.data.data(), img.pixel_count(), n);
    layer.coefficients.k = k;
    const Eigen::MatrixXf b = basis_columns(basis, k);
    layer.coefficients.basis.assign(b.data(), b.data() + b.size());
    layer.coefficients.values = project_coefficients(basis, k, layer.data.data(), img.pixel_count());
    for (float& v : layer.coefficients.values) v = half(v);  // what the file holds (as compress stores them)
    layer.coefficients.errors = {{"D65", 0.125, 0.5}, {"A", 0.25, 0.75}};
    img.lights.push_back(std::move(layer));
  }
  img.coefficient_criterion = R"({"maxDeltaE00":0.5,"percentile":99.0})";
  return img;
}

ExrReadOptions with_coefficients() {
  ExrReadOptions o;
  o.read_coefficients = true;
  return o;
}

ExrReadOptions compact_ok() {
  ExrReadOptions o = with_coefficients();
  o.allow_compact = true;
  return o;
}

void expect_same_coefficients(const SpectralImage& a, const SpectralImage& b) {
  ASSERT_EQ(a.lights.size(), b.lights.size());
  for (std::size_t l = 0; l < a.lights.size(); ++l) {
    const auto& ca = a.lights[l].coefficients;
    const auto& cb = b.lights[l].coefficients;
    EXPECT_EQ(a.lights[l].name, b.lights[l].name);
    EXPECT_EQ(ca.k, cb.k);
    EXPECT_EQ(ca.basis, cb.basis);
    EXPECT_EQ(ca.values, cb.values);
    ASSERT_EQ(ca.errors.size(), cb.errors.size());
    for (std::size_t i = 0; i < ca.errors.size(); ++i) {
      EXPECT_EQ(ca.errors[i].light, cb.errors[i].light);
      EXPECT_EQ(ca.errors[i].percentile, cb.errors[i].percentile);
      EXPECT_EQ(ca.errors[i].max, cb.errors[i].max);
    }
  }
}

// Rewrites `path` with one value of `channel` changed (every attribute kept, prizma:checksum too).
void damage_channel(const fs::path& path, const std::string& channel) {
  std::map<std::string, std::vector<float>> values;
  Imf::Header header;
  {
    Imf::InputFile in(path.c_str());
    header = in.header();
    const Imath::Box2i dw = header.dataWindow();
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    Imf::FrameBuffer fb;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
      auto& v = values[it.name()];
      v.assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 0.0f);
      fb.insert(it.name(), Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(v.data()), sizeof(float),
                                      sizeof(float) * static_cast<std::size_t>(w)));
    }
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
  }
  ASSERT_TRUE(values.count(channel)) << channel;
  values[channel][5] += 0.25f;
  const Imath::Box2i dw = header.dataWindow();
  const int w = dw.max.x - dw.min.x + 1;
  for (auto it = header.channels().begin(); it != header.channels().end(); ++it) it.channel().type = Imf::FLOAT;
  Imf::OutputFile out(path.c_str(), header);
  Imf::FrameBuffer fb;
  for (auto& [name, v] : values) {
    fb.insert(name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(v.data()), sizeof(float),
                               sizeof(float) * static_cast<std::size_t>(w)));
  }
  out.setFrameBuffer(fb);
  out.writePixels(dw.max.y - dw.min.y + 1);
}

TEST_F(CoefficientsExr, RoundTripKeepsBinsAndCoefficients) {
  const SpectralImage img = image_with_coefficients(2, 3);
  write_spectral_exr(file("c.exr"), img);
  const SpectralImage back = read_spectral_exr(file("c.exr"), with_coefficients());
  EXPECT_FALSE(back.compact());
  EXPECT_TRUE(back.has_coefficients());
  for (std::size_t l = 0; l < img.lights.size(); ++l) EXPECT_EQ(back.lights[l].data, img.lights[l].data);
  expect_same_coefficients(img, back);
  EXPECT_NE(back.coefficient_criterion.find("\"maxDeltaE00\":0.5"), std::string::npos) << back.coefficient_criterion;
  // The stored checksum covers them: it is the checksum of the image read with them.
  Imf::InputFile raw(file("c.exr").c_str());
  const auto* stored = raw.header().findTypedAttribute<Imf::StringAttribute>("prizma:checksum");
  ASSERT_NE(stored, nullptr);
  EXPECT_EQ(stored->value(), spectral_pixel_checksum(back));
  // Without the coefficients the checksum of the bins alone differs.
  SpectralImage bins_only = back;
  for (auto& l : bins_only.lights) l.coefficients = {};
  EXPECT_NE(stored->value(), spectral_pixel_checksum(bins_only));
}

TEST_F(CoefficientsExr, DefaultReadVerifiesThemAndLeavesThemOut) {
  const SpectralImage img = image_with_coefficients(2, 3);
  write_spectral_exr(file("c.exr"), img);
  const SpectralImage back = read_spectral_exr(file("c.exr"));
  EXPECT_FALSE(back.has_coefficients());
  for (const auto& l : back.lights) {
    EXPECT_EQ(l.coefficients.k, 0);
    EXPECT_TRUE(l.coefficients.values.empty());
  }
  EXPECT_TRUE(back.coefficient_criterion.empty());
  // Rewriting such an image writes no stale coefficients.
  write_spectral_exr(file("again.exr"), back);
  EXPECT_FALSE(read_spectral_exr(file("again.exr"), with_coefficients()).has_coefficients());
}

TEST_F(CoefficientsExr, CompactRoundTripHasNoBins) {
  for (int lights : {1, 2}) {
    SCOPED_TRACE(lights);
    SpectralImage img = image_with_coefficients(lights, 4);
    for (auto& l : img.lights) l.data.clear();
    ASSERT_TRUE(img.compact());
    write_spectral_exr(file("compact.exr"), img);
    {
      Imf::InputFile raw(file("compact.exr").c_str());
      for (auto it = raw.header().channels().begin(); it != raw.header().channels().end(); ++it) {
        const std::string name = it.name();
        EXPECT_TRUE(name.find("coef.") != std::string::npos || name == "R" || name == "G" || name == "B") << name;
      }
    }
    const SpectralImage back = read_spectral_exr(file("compact.exr"), compact_ok());
    EXPECT_TRUE(back.compact());
    EXPECT_EQ(back.bins.edges_nm(), img.bins.edges_nm());
    EXPECT_EQ(back.width, img.width);
    EXPECT_EQ(back.height, img.height);
    expect_same_coefficients(img, back);
    // Every other reader is told what the file is.
    try {
      (void)read_spectral_exr(file("compact.exr"));
      FAIL() << "a compact file read without allow_compact";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("compact file"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("prizma-relight"), std::string::npos) << e.what();
    }
  }
}

TEST_F(CoefficientsExr, DamagedCoefficientChannelIsRefused) {
  const SpectralImage img = image_with_coefficients(2, 3);
  write_spectral_exr(file("c.exr"), img);
  damage_channel(file("c.exr"), "fill.coef.1");
  for (const ExrReadOptions& o : {ExrReadOptions{}, with_coefficients()}) {
    try {
      (void)read_spectral_exr(file("c.exr"), o);
      FAIL() << "damaged coefficients read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("do not match prizma:checksum"), std::string::npos) << e.what();
    }
  }
  ExrReadOptions no_verify = with_coefficients();
  no_verify.verify_checksum = false;
  EXPECT_NE(read_spectral_exr(file("c.exr"), no_verify).lights[1].coefficients.values, img.lights[1].coefficients.values);
  // The same in a compact file.
  SpectralImage compact = img;
  for (auto& l : compact.lights) l.data.clear();
  write_spectral_exr(file("compact.exr"), compact);
  damage_channel(file("compact.exr"), "key.coef.0");
  EXPECT_THROW((void)read_spectral_exr(file("compact.exr"), compact_ok()), InputError);
}

TEST_F(CoefficientsExr, WriterRefusesInconsistentCoefficients) {
  SpectralImage img = image_with_coefficients(2, 3);
  img.lights[1].coefficients = {};
  EXPECT_THROW(write_spectral_exr(file("a.exr"), img), InputError);  // one layer without them
  img = image_with_coefficients(2, 3);
  img.lights[0].coefficients.basis.pop_back();
  EXPECT_THROW(write_spectral_exr(file("b.exr"), img), InputError);
  img = image_with_coefficients(2, 3);
  img.lights[0].coefficients.values[4] = std::nanf("");
  EXPECT_THROW(write_spectral_exr(file("c.exr"), img), InputError);
  EXPECT_FALSE(fs::exists(file("a.exr")) || fs::exists(file("b.exr")) || fs::exists(file("c.exr")));
}

TEST_F(CoefficientsExr, ReaderRefusesAMissingBasisOrAGap) {
  const SpectralImage img = image_with_coefficients(2, 3);
  write_spectral_exr(file("c.exr"), img);
  // Rewrite the header without one basis, and with a channel renamed away (a gap).
  auto rewrite = [&](const std::string& out, auto edit) {
    Imf::InputFile in(file("c.exr").c_str());
    Imf::Header header = in.header();
    const Imath::Box2i dw = header.dataWindow();
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    std::map<std::string, std::vector<float>> values;
    Imf::FrameBuffer fb;
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
      auto& v = values[it.name()];
      v.assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), 0.0f);
      fb.insert(it.name(), Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(v.data()), sizeof(float), sizeof(float) * w));
    }
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    edit(header, values);
    for (auto it = header.channels().begin(); it != header.channels().end(); ++it) it.channel().type = Imf::FLOAT;
    Imf::OutputFile o(file(out).c_str(), header);
    Imf::FrameBuffer ofb;
    for (auto& [name, v] : values)
      ofb.insert(name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(v.data()), sizeof(float), sizeof(float) * w));
    o.setFrameBuffer(ofb);
    o.writePixels(h);
  };
  rewrite("nobasis.exr", [](Imf::Header& h, auto&) { h.erase("prizma:basis.fill"); });
  rewrite("gap.exr", [](Imf::Header& h, auto& values) {
    Imf::ChannelList list;
    for (auto it = h.channels().begin(); it != h.channels().end(); ++it)
      if (std::string(it.name()) != "key.coef.1") list.insert(it.name(), it.channel());
    h.channels() = list;
    values.erase("key.coef.1");
  });
  for (const auto& [name, reason] : {std::pair<std::string, std::string>{"nobasis.exr", "no basis"},
                                     {"gap.exr", "not numbered 0..1"}}) {
    try {
      (void)read_spectral_exr(file(name), with_coefficients());
      FAIL() << name;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
    }
  }
}

// The coefficient channels are half: float values are rounded to the nearest half on write (the
// checksum covers the rounded values, so the file verifies), and values half cannot hold are refused
// before anything is written.
TEST_F(CoefficientsExr, ChannelsAreHalfRoundedOnWriteAndRangeChecked) {
  SpectralImage img = image_with_coefficients(2, 3);
  img.lights[1].coefficients.values[7] = 0.1f;  // not a half: rounds to 0.0999755859375
  write_spectral_exr(file("h.exr"), img);
  {
    Imf::InputFile in(file("h.exr").c_str());
    int coefficient_channels = 0;
    for (auto it = in.header().channels().begin(); it != in.header().channels().end(); ++it) {
      if (std::string(it.name()).find("coef.") == std::string::npos) continue;
      ++coefficient_channels;
      EXPECT_EQ(it.channel().type, Imf::HALF) << it.name();
    }
    EXPECT_EQ(coefficient_channels, 6);
  }
  const SpectralImage back = read_spectral_exr(file("h.exr"), with_coefficients());  // checksum verified
  EXPECT_EQ(back.lights[1].coefficients.values[7], 0.0999755859375f);
  EXPECT_EQ(back.lights[0].coefficients.values, img.lights[0].coefficients.values);
  EXPECT_EQ(back.lights[0].data, img.lights[0].data) << "the bins stay float";

  img.lights[0].coefficients.values[3 * 13 + 2] = 70000.0f;  // pixel (1, 1), coefficient 2
  try {
    write_spectral_exr(file("big.exr"), img);
    FAIL() << "a coefficient beyond half's range was written";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("coefficients of light \"key\""), std::string::npos) << m;
    EXPECT_NE(m.find("pixel (1, 1), coefficient 2"), std::string::npos) << m;
    EXPECT_NE(m.find("65504"), std::string::npos) << m;
  }
  EXPECT_FALSE(fs::exists(file("big.exr")));
}

}  // namespace
}  // namespace prizma::spectral
