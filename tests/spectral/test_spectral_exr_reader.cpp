// The spectral EXR reader: the published single-layer layout written by plain OpenEXR code, bin
// edges (inferred, recorded in every numeric form, refused when they disagree), data windows.
#include "spectral_exr_test_support.h"

using namespace prizma::spectral;
using namespace prizma::spectral::exr_test;

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
