// The spectral EXR layer kinds: light layers with and without variance, the preview R,G,B (the
// default relight), emission, the prizma:lights record that names the layers.
#include "spectral_exr_test_support.h"

using namespace prizma::spectral;
using namespace prizma::spectral::exr_test;

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
