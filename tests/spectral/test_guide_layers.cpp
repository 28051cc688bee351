// Guide layers in the spectral EXR (docs/spectral-exr.md, "Guide layers"): the denoiser's
// light-independent planes guide.<name> and guide.<name>.var round-trip exactly, the checksum covers
// them, a file without them is written as before, the published layout's reader cannot take them
// for spectra, and prizma:denoised round-trips.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <gtest/gtest.h>

#include <regex>
#include <string>
#include <vector>

#include "prizma/spectral/error.h"
#include "prizma/spectral/spectral_exr.h"
#include "scratch_files.h"

namespace prizma::spectral {
namespace {

namespace fs = std::filesystem;

SpectralImage two_light_image() {
  SpectralImage img;
  img.width = 5;
  img.height = 3;
  img.bins = BinLayout::linear(400.0, 700.0, 4);
  for (const char* name : {"key", "fill"}) {
    TransportLayer& l = img.lights.emplace_back();
    l.name = name;
    for (std::size_t k = 0; k < img.pixel_count() * 4; ++k) {
      l.data.push_back(0.01f * static_cast<float>(k) + (name[0] == 'k' ? 0.5f : 0.25f));
      l.variance.push_back(1e-4f * static_cast<float>(k % 7));
    }
  }
  img.info.samples = 16;
  return img;
}

void add_guides(SpectralImage& img) {
  GuideLayer depth{"depth", {}, {}}, scatter{"scatter", {}, {}};
  for (std::size_t p = 0; p < img.pixel_count(); ++p) {
    depth.value.push_back(0.1f + 0.05f * static_cast<float>(p));
    depth.variance.push_back(1e-3f * static_cast<float>(p % 3));
    scatter.value.push_back(p % 2 == 0 ? 1.0f : 0.375f);
  }
  img.guides = {depth, scatter};  // scatter without a variance plane: allowed
}

std::vector<std::string> channel_names(const fs::path& p) {
  Imf::InputFile in(p.c_str());
  std::vector<std::string> names;
  for (auto it = in.header().channels().begin(); it != in.header().channels().end(); ++it) names.emplace_back(it.name());
  return names;
}

TEST(GuideLayers, RoundTripExactlyAndNamedAsDocumented) {
  const fs::path dir = test::scratch_dir("guides", "round_trip");
  SpectralImage img = two_light_image();
  add_guides(img);
  img.info.denoised = R"({"method":"non-local means","variance":"propagated"})";
  write_spectral_exr(dir / "g.exr", img);
  const SpectralImage back = read_spectral_exr(dir / "g.exr");
  EXPECT_EQ(back.guides, img.guides);  // sorted by name: depth, scatter
  EXPECT_EQ(back.lights[0].data, img.lights[0].data);
  EXPECT_EQ(back.lights[1].variance, img.lights[1].variance);
  EXPECT_EQ(back.info.denoised, img.info.denoised);
  EXPECT_EQ(spectral_pixel_checksum(back), spectral_pixel_checksum(img));
  const std::vector<std::string> names = channel_names(dir / "g.exr");
  for (const char* c : {"guide.depth", "guide.depth.var", "guide.scatter"})
    EXPECT_NE(std::find(names.begin(), names.end(), c), names.end()) << c;
  EXPECT_EQ(std::find(names.begin(), names.end(), "guide.scatter.var"), names.end());
  // Half files keep the guides in float: their values come back exactly.
  ExrWriteOptions half;
  half.pixel_type = ExrPixelType::Half;
  write_spectral_exr(dir / "h.exr", img, half);
  EXPECT_EQ(read_spectral_exr(dir / "h.exr").guides, img.guides);
}

// The checksum covers the guides (a term of its own, from its own basis): an image with guides has
// another checksum than the same image without, and changing one guide value changes it. Without
// guides the checksum is what it was before guides existed (the term is 0).
TEST(GuideLayers, TheChecksumCoversThem) {
  SpectralImage plain = two_light_image();
  SpectralImage guided = plain;
  add_guides(guided);
  EXPECT_NE(spectral_pixel_checksum(plain), spectral_pixel_checksum(guided));
  SpectralImage changed = guided;
  changed.guides[0].value[4] = std::nextafter(changed.guides[0].value[4], 2.0f);
  EXPECT_NE(spectral_pixel_checksum(changed), spectral_pixel_checksum(guided));
  SpectralImage var_changed = guided;
  var_changed.guides[0].variance[2] += 1e-6f;
  EXPECT_NE(spectral_pixel_checksum(var_changed), spectral_pixel_checksum(guided));
}

// A guide channel damaged on disk (rewritten by another program with the header kept) is refused.
TEST(GuideLayers, ADamagedGuideIsRefused) {
  const fs::path dir = test::scratch_dir("guides", "damaged");
  SpectralImage img = two_light_image();
  add_guides(img);
  write_spectral_exr(dir / "g.exr", img);
  Imf::InputFile in((dir / "g.exr").c_str());
  const Imf::Header header = in.header();
  const auto dw = header.dataWindow();
  // Copy every channel as float, one guide value changed.
  std::vector<std::vector<float>> planes;
  Imf::FrameBuffer fb;
  const std::vector<std::string> names = channel_names(dir / "g.exr");
  planes.reserve(names.size());
  for (const std::string& c : names) {
    auto& plane = planes.emplace_back(img.pixel_count());
    fb.insert(c, Imf::Slice::Make(Imf::FLOAT, plane.data(), dw, sizeof(float), sizeof(float) * 5));
  }
  in.setFrameBuffer(fb);
  in.readPixels(dw.min.y, dw.max.y);
  Imf::Header out_header = header;
  for (auto it = out_header.channels().begin(); it != out_header.channels().end(); ++it) it.channel().type = Imf::FLOAT;
  const auto at = std::find(names.begin(), names.end(), "guide.depth") - names.begin();
  planes[static_cast<std::size_t>(at)][3] += 0.5f;
  {
    Imf::OutputFile out((dir / "bad.exr").c_str(), out_header);
    out.setFrameBuffer(fb);
    out.writePixels(img.height);
  }
  try {
    read_spectral_exr(dir / "bad.exr");
    FAIL() << "a damaged guide was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("pixel data do not match prizma:checksum"), std::string::npos) << e.what();
  }
  ExrReadOptions unverified;
  unverified.verify_checksum = false;
  EXPECT_EQ(read_spectral_exr(dir / "bad.exr", unverified).guides[0].value[3], img.guides[0].value[3] + 0.5f);
}

// The published layout (Fichet, Pacanowski, Wilkie, JCGT 2021) names a spectral channel
// [<layer>.](T|S0..S3).<number><unit prefix>(m|Hz); a reader of it (the reference code, Prizma's
// exr/channel_names.cpp) takes a channel for a spectrum only when it matches. This is that pattern
// with any layer name: no guide channel matches it, so they are extra channels to such a reader,
// never spectra. Ours keeps every channel it should: the lights, variances and guides of the file.
TEST(GuideLayers, TheReferenceReaderCannotTakeThemForSpectra) {
  const std::regex reference(R"(^((.+)\.)?(S[0-3]|T)\.(\d*,?\d*([Ee][+-]?\d+)?)(Y|Z|E|P|T|G|M|k|h|da|d|c|m|u|n|p)?(m|Hz)$)");
  const fs::path dir = test::scratch_dir("guides", "reference");
  SpectralImage img = two_light_image();
  add_guides(img);
  write_spectral_exr(dir / "g.exr", img);
  int spectral = 0;
  for (const std::string& c : channel_names(dir / "g.exr")) {
    const bool guide = c.rfind("guide.", 0) == 0;
    if (guide) {
      EXPECT_FALSE(std::regex_match(c, reference)) << c;
    } else if (std::regex_match(c, reference)) {
      ++spectral;
    }
  }
  EXPECT_EQ(spectral, 4 * 5);  // T, key.T, fill.T, key.var.T, fill.var.T: 4 bins each
  const SpectralImage back = read_spectral_exr(dir / "g.exr");
  ASSERT_EQ(back.lights.size(), 2u);
  EXPECT_EQ(back.guides.size(), 2u);
}

TEST(GuideLayers, WhatTheWriterRefuses) {
  const fs::path dir = test::scratch_dir("guides", "refused");
  auto refused = [&](SpectralImage img, const std::string& what) {
    try {
      write_spectral_exr(dir / "r.exr", img);
      ADD_FAILURE() << "written: " << what;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir / "r.exr"));
  };
  SpectralImage img = two_light_image();
  add_guides(img);
  SpectralImage bad_name = img;
  bad_name.guides[0].name = "de.pth";
  refused(bad_name, "guide \"de.pth\": a guide's name is letters, digits and '_'");
  SpectralImage twice = img;
  twice.guides[1].name = "depth";
  refused(twice, "two guides are named \"depth\"");
  SpectralImage short_plane = img;
  short_plane.guides[0].value.pop_back();
  refused(short_plane, "guide \"depth\": 14 values and 15 variances for 15 pixels");
  SpectralImage negative = img;
  negative.guides[0].variance[1] = -1.0f;
  refused(negative, "guide \"depth\" variance: value -1");
}

}  // namespace
}  // namespace prizma::spectral
