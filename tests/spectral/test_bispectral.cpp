// Bispectral (re-radiation) channels T.<λin>nm.<λout>nm (docs/spectral-exr.md): names, a round trip
// through the file per light layer, files written by another tool with the reference layout's
// channels only, and the errors.
#include <gtest/gtest.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <system_error>
#include <vector>

#include "prizma/spectral/bispectral.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/spectral_exr.h"

namespace prizma::spectral {
namespace {

namespace fs = std::filesystem;

// A file in the temporary folder, named after the process, removed when the test ends.
class Scratch {
 public:
  explicit Scratch(const std::string& name)
      : m_path(fs::temp_directory_path() / ("prizma-bispectral-" + std::to_string(::getpid()) + "-" + name)) {}
  ~Scratch() {
    std::error_code ec;
    fs::remove(m_path, ec);
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
  const fs::path& path() const { return m_path; }

 private:
  fs::path m_path;
};

// 3×2 pixels, 4 bins over 400–600 nm, pairs (0→2), (0→3), (1→3).
SpectralImage bispectral_image(const std::vector<std::string>& names) {
  SpectralImage img;
  img.width = 3;
  img.height = 2;
  img.bins = BinLayout::linear(400, 600, 4);
  img.reradiation = {{0, 2}, {0, 3}, {1, 3}};
  for (std::size_t l = 0; l < names.size(); ++l) {
    TransportLayer t;
    t.name = names[l];
    for (std::size_t k = 0; k < img.pixel_count() * 4; ++k) t.data.push_back(0.1f * static_cast<float>(k + l));
    for (std::size_t k = 0; k < img.pixel_count() * 3; ++k) t.reradiation.push_back(0.01f * static_cast<float>(k + 7 * l + 1));
    img.lights.push_back(t);
  }
  return img;
}

TEST(Bispectral, ChannelNamesPutTheExcitationFirst) {
  EXPECT_EQ(reradiation_channel_name(425.0, 575.0), "T.425,000000nm.575,000000nm");
  EXPECT_EQ(reradiation_channel_name(425.0, 575.0, "uv"), "uv.T.425,000000nm.575,000000nm");
}

TEST(Bispectral, RoundTripPerLightLayer) {
  for (const auto& names : {std::vector<std::string>{"uv"}, std::vector<std::string>{"uv", "sky"}}) {
    const SpectralImage img = bispectral_image(names);
    const Scratch file("round.exr");
    const fs::path& p = file.path();
    write_spectral_exr(p, img);
    const SpectralImage back = read_spectral_exr(p);
    EXPECT_EQ(back.reradiation, img.reradiation);
    ASSERT_EQ(back.lights.size(), names.size());
    for (std::size_t l = 0; l < names.size(); ++l) {
      EXPECT_EQ(back.lights[l].data, img.lights[l].data);
      EXPECT_EQ(back.lights[l].reradiation, img.lights[l].reradiation);
    }
    EXPECT_EQ(spectral_pixel_checksum(back), spectral_pixel_checksum(img));
  }
}

TEST(Bispectral, ChecksumCoversTheBispectralValues) {
  SpectralImage img = bispectral_image({"uv"});
  const std::string before = spectral_pixel_checksum(img);
  img.lights[0].reradiation[4] += 0.5f;
  EXPECT_NE(spectral_pixel_checksum(img), before);
  // A diagonal image's checksum is what it was before bispectral channels existed.
  SpectralImage diag = bispectral_image({"uv"});
  const std::string with = spectral_pixel_checksum(diag);
  diag.reradiation.clear();
  diag.lights[0].reradiation.clear();
  EXPECT_NE(spectral_pixel_checksum(diag), with);
}

TEST(Bispectral, HalfFilesRoundTripTheHalfValues) {
  const SpectralImage img = bispectral_image({"uv", "sky"});
  const Scratch file("half.exr");
  const fs::path& p = file.path();
  ExrWriteOptions o;
  o.pixel_type = ExrPixelType::Half;
  write_spectral_exr(p, img, o);
  const SpectralImage back = read_spectral_exr(p);  // the checksum holds for the half values
  ASSERT_EQ(back.reradiation, img.reradiation);
  for (std::size_t k = 0; k < img.lights[1].reradiation.size(); ++k)
    EXPECT_NEAR(back.lights[1].reradiation[k], img.lights[1].reradiation[k], 1e-3f * img.lights[1].reradiation[k]);
}

// issue 25 item 11: the JCGT reference library reads a file's re-radiation (its top-level channels
// T.<λin>nm.<λout>nm) only when they are every pair with λin < λout of its T.<λ>nm wavelengths and no
// other (EXRBiSpectralImage reads exactly n(n−1)/2 channels; a missing or a reversed pair crashed
// it). Prizma writes the top level that way — the lights' sum, 0 where it holds nothing, no reversed
// pair — and keeps every pair it holds, the reversed one too, in the light layers it reads back.
TEST(Bispectral, TopLevelIsTheReferenceLayoutsFullUpperTriangle) {
  for (const auto& names : {std::vector<std::string>{"uv"}, std::vector<std::string>{"uv", "sky"}}) {
    SpectralImage img = bispectral_image(names);
    img.reradiation = {{0, 2}, {0, 3}, {1, 3}, {3, 1}};  // (3 → 1): overlapping spectra, λin > λout
    for (auto& light : img.lights) {
      for (std::size_t px = 0; px < img.pixel_count(); ++px) light.reradiation.push_back(0.5f + 0.01f * static_cast<float>(px));
      std::vector<float> interleaved;  // pairs contiguous per pixel: 3 old values, then the new one
      for (std::size_t px = 0; px < img.pixel_count(); ++px) {
        for (int q = 0; q < 3; ++q) interleaved.push_back(light.reradiation[px * 3 + static_cast<std::size_t>(q)]);
        interleaved.push_back(light.reradiation[img.pixel_count() * 3 + px]);
      }
      light.reradiation = interleaved;
    }
    std::sort(img.reradiation.begin(), img.reradiation.end(),
              [](const BinPair& a, const BinPair& b) { return a.in != b.in ? a.in < b.in : a.out < b.out; });
    // (sorted: (0,2) (0,3) (1,3) (3,1): the order the values were laid out in)
    const Scratch file("published.exr");
    write_spectral_exr(file.path(), img);

    // The top level, as the reference reader sees it: the diagonal and exactly the 6 pairs in < out.
    Imf::InputFile in(file.path().c_str());
    std::vector<std::string> top_pairs;
    for (auto it = in.header().channels().begin(); it != in.header().channels().end(); ++it) {
      const std::string name = it.name();
      if (name.rfind("T.", 0) == 0 && std::count(name.begin(), name.end(), 'n') == 2) top_pairs.push_back(name);
    }
    std::vector<std::string> expected;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) expected.push_back(reradiation_channel_name(img.bins.centre_nm(a), img.bins.centre_nm(b)));
    std::sort(expected.begin(), expected.end());
    EXPECT_EQ(top_pairs, expected) << names.size() << " lights";
    // Their values: the lights' sum for the pairs held, 0 for the others.
    const auto dw = in.header().dataWindow();
    std::vector<float> v02(img.pixel_count()), v12(img.pixel_count(), -1.0f);
    Imf::FrameBuffer fb;
    fb.insert(reradiation_channel_name(img.bins.centre_nm(0), img.bins.centre_nm(2)), Imf::Slice::Make(Imf::FLOAT, v02.data(), dw, sizeof(float), sizeof(float) * 3));
    fb.insert(reradiation_channel_name(img.bins.centre_nm(1), img.bins.centre_nm(2)), Imf::Slice::Make(Imf::FLOAT, v12.data(), dw, sizeof(float), sizeof(float) * 3));
    in.setFrameBuffer(fb);
    in.readPixels(dw.min.y, dw.max.y);
    for (std::size_t px = 0; px < img.pixel_count(); ++px) {
      double sum = 0.0;
      for (const auto& light : img.lights) sum += light.reradiation[px * 4 + 0];
      EXPECT_EQ(v02[px], static_cast<float>(sum)) << px;
      EXPECT_EQ(v12[px], 0.0f) << px;  // (1 → 2) held by no light
    }
    // Prizma reads back what it holds, the reversed pair included, from the light layers.
    const SpectralImage back = read_spectral_exr(file.path());
    EXPECT_EQ(back.reradiation, img.reradiation);
    for (std::size_t l = 0; l < names.size(); ++l) EXPECT_EQ(back.lights[l].reradiation, img.lights[l].reradiation);
    EXPECT_EQ(back.lights[0].name, "uv");
  }
}

// A file as another tool writes the reference layout: no prizma: attributes, wavelengths in other
// units, only some pairs.
TEST(Bispectral, ReadsAReferenceLayoutFileFromAnotherWriter) {
  const Scratch file("other.exr");
  const fs::path& p = file.path();
  const int w = 2, h = 1;
  const std::vector<std::string> diag = {"T.500nm", "T.550nm", "T.600nm", "T.650nm"};
  const std::vector<std::string> rerad = {"T.500nm.600nm", "T.0,5um.650nm", "T.550nm.6,5E2nm"};
  std::vector<float> values(static_cast<std::size_t>(w * h) * (diag.size() + rerad.size()));
  for (std::size_t k = 0; k < values.size(); ++k) values[k] = 0.25f + static_cast<float>(k);
  {
    Imf::Header header(w, h);
    header.insert("spectralLayoutVersion", Imf::StringAttribute("1.0"));
    Imf::FrameBuffer fb;
    const std::size_t nc = diag.size() + rerad.size();
    std::size_t c = 0;
    for (const auto* list : {&diag, &rerad})
      for (const std::string& name : *list) {
        header.channels().insert(name, Imf::Channel(Imf::FLOAT));
        fb.insert(name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(values.data() + c), sizeof(float) * nc,
                                   sizeof(float) * nc * w));
        ++c;
      }
    Imf::OutputFile out(p.c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(h);
  }
  const SpectralImage img = read_spectral_exr(p);
  ASSERT_EQ(img.bins.size(), 4);
  const std::vector<BinPair> want = {{0, 2}, {0, 3}, {1, 3}};
  ASSERT_EQ(img.reradiation, want);
  const std::size_t nc = 7;
  for (std::size_t px = 0; px < 2; ++px) {
    EXPECT_EQ(img.lights[0].reradiation[px * 3 + 0], values[px * nc + 4]);  // T.500nm.600nm
    EXPECT_EQ(img.lights[0].reradiation[px * 3 + 1], values[px * nc + 5]);  // T.0,5um.650nm
    EXPECT_EQ(img.lights[0].reradiation[px * 3 + 2], values[px * nc + 6]);  // T.550nm.6,5E2nm
  }
}

TEST(Bispectral, WriterRefusesBadPairsAndValues) {
  const Scratch bad("bad.exr");
  auto expect_refused = [&](const SpectralImage& img, const std::string& reason) {
    try {
      write_spectral_exr(bad.path(), img);
      FAIL() << "written; expected " << reason;
    } catch (const InputError& e) {
      EXPECT_NE(e.reason().find(reason), std::string::npos) << e.what();
    }
  };
  SpectralImage img = bispectral_image({"uv"});
  img.reradiation[1] = {2, 2};
  expect_refused(img, "on the diagonal");
  img = bispectral_image({"uv"});
  img.reradiation[1] = {0, 9};
  expect_refused(img, "outside the 4 bins");
  img = bispectral_image({"uv"});
  std::swap(img.reradiation[0], img.reradiation[1]);
  expect_refused(img, "not sorted");
  img = bispectral_image({"uv"});
  img.lights[0].reradiation.pop_back();
  expect_refused(img, "bispectral values, expected");
  img = bispectral_image({"uv"});
  img.lights[0].reradiation[2] = std::numeric_limits<float>::quiet_NaN();
  expect_refused(img, "NaN at pixel (0, 0)");
  EXPECT_FALSE(fs::exists(bad.path()));
}

TEST(Bispectral, AddReradiatedIsTheMatrixTimesTheLight) {
  const SpectralImage img = bispectral_image({"uv"});
  const std::vector<double> e = {2.0, 3.0, 5.0, 7.0};
  std::vector<double> rad(img.pixel_count() * 4, 0.0);
  add_reradiated(img, 0, e, rad);
  const auto& m = img.lights[0].reradiation;
  for (std::size_t px = 0; px < img.pixel_count(); ++px) {
    EXPECT_DOUBLE_EQ(rad[px * 4 + 0], 0.0);
    EXPECT_DOUBLE_EQ(rad[px * 4 + 2], double(m[px * 3 + 0]) * 2.0);
    EXPECT_DOUBLE_EQ(rad[px * 4 + 3], double(m[px * 3 + 1]) * 2.0 + double(m[px * 3 + 2]) * 3.0);
  }
}

}  // namespace
}  // namespace prizma::spectral
