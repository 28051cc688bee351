// RelightSession, the interactive shell driven through a stream, batch files and output files.
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <iterator>
#include <regex>
#include <sstream>

#include "prizma/relight/batch_file.h"
#include "prizma/relight/interactive_shell.h"
#include "prizma/spectral/relight_image.h"
#include "prizma/relight/relight_session.h"
#include "prizma/relight/serve_state.h"
#include "prizma/spectral/colour.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/input_file.h"
#include "spectral/relight_test_util.h"

namespace prizma::relight {
namespace {

namespace fs = std::filesystem;
using spectral::BinLayout;

// A 6×4 two-light file: key lights the left half grey (T = 0.5), back lights the right half with a
// red-ish transport; pixel (5, 3) is black under both.
fs::path write_fixture(const fs::path& dir) {
  const BinLayout bins = BinLayout::linear(400.0, 700.0, 12);
  auto img = spectral::test::make_image(6, 4, bins, {"key", "back"}, [](int l, int p, int i) {
    const int x = p % 6;
    if (p == 23) return 0.0f;
    if (l == 0) return x < 3 ? 0.5f : 0.0f;
    return x >= 3 ? static_cast<float>(i) / 11.0f : 0.0f;
  });
  img.info.light_records = prizma::spectral::parse_light_records(R"([{"name":"key","direction":[0,0,1],"angularSizeDeg":0,"spectrum":"D65"},
                             {"name":"back","direction":[0,1,0],"angularSizeDeg":0,"spectrum":"A*0.5"}])", "test");
  const fs::path path = dir / "scene.exr";
  spectral::write_spectral_exr(path, img);
  return path;
}

std::vector<float> read_pixels(const fs::path& path, int& channels, OIIO::ImageSpec* spec_out = nullptr) {
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) return {};
  const OIIO::ImageSpec& spec = in->spec();
  channels = spec.nchannels;
  std::vector<float> px(static_cast<std::size_t>(spec.width) * spec.height * spec.nchannels);
  in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data());
  if (spec_out) *spec_out = spec;
  return px;
}

// The exposure and bit-depth limits are RelightSettings::validate's alone (issue 22): every front end
// refuses the same values with the same words, naming the value as its user gave it. The page's state
// said "must be within ±64 stops", a session's bit depth "must be 8 or 16, not 12".
TEST(RelightSettings, EveryFrontEndRefusesWithTheOneCheck) {
  const fs::path dir = spectral::test::scratch_dir("validate");
  RelightSession session(write_fixture(dir));
  auto error = [](const std::function<void()>& f) {
    try {
      f();
    } catch (const spectral::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string range = ": must be a finite number of stops within ±64";
  EXPECT_EQ(error([&] { session.set_exposure(64.5); }), "exposure" + range);
  EXPECT_EQ(error([&] { settings_from_state({{"exposure", "65"}}, session, session.settings()); }), "state: exposure" + range);
  auto batch = [&](const std::string& json) {
    std::ofstream(dir / "b.json") << json;
    return error([&] { read_batch_file(dir / "b.json", session, session.settings()); });
  };
  const std::string b = (dir / "b.json").string();
  EXPECT_EQ(batch(R"({"outputs": [{"file": "a.png", "exposure": -70}]})"), b + ": outputs[0].exposure" + range);
  EXPECT_EQ(batch(R"({"defaults": {"exposure": 1e300}, "outputs": [{"file": "a.png"}]})"), b + ": defaults.exposure" + range);
  EXPECT_EQ(batch(R"({"outputs": [{"file": "a.png", "bitDepth": 24}]})"), b + ": outputs[0].bitDepth: must be 8 or 16 (got 24)");
  RelightSettings s = session.settings();
  s.output.bit_depth = 12;
  EXPECT_EQ(error([&] { session.apply(s, {"--exposure", "--bit-depth"}); }), "--bit-depth: must be 8 or 16 (got 12)");
  s.output.bit_depth = 16;
  s.relight.exposure_ev = -64.0;  // the limit itself is allowed
  EXPECT_EQ(error([&] { session.apply(s); }), "no error");
  s.relight.exposure_ev = std::nan("");
  EXPECT_EQ(error([&] { s.validate({"--exposure", "--bit-depth"}); }), "--exposure" + range);
}

TEST(RelightSession, LoadsDefaultsFromPrizmaLights) {
  const fs::path dir = spectral::test::scratch_dir("defaults");
  RelightSession session(write_fixture(dir));
  ASSERT_EQ(session.light_names(), (std::vector<std::string>{"key", "back"}));
  EXPECT_EQ(session.settings().lights[0].text, "D65");
  EXPECT_EQ(session.settings().lights[1].text, "A*0.5");
  EXPECT_DOUBLE_EQ(session.settings().lights[1].scale, 0.5);
}

// A file rendered elsewhere may record a light as a CSV that is not here: it still opens, relighting
// with that default fails naming the light, and giving the light a spectrum makes it work.
TEST(RelightSession, UnusableRecordedLightFailsOnlyWhenUsed) {
  const fs::path dir = spectral::test::scratch_dir("unusable_default");
  const BinLayout bins = BinLayout::linear(400.0, 700.0, 12);
  auto img = spectral::test::make_image(6, 4, bins, {"key", "back"}, [](int, int, int) { return 0.5f; });
  img.info.light_records = prizma::spectral::parse_light_records(R"([{"name":"key","spectrum":"D65"},{"name":"back","spectrum":"csv:/nowhere/lamp.csv*2"}])", "test");
  const fs::path path = dir / "elsewhere.exr";
  spectral::write_spectral_exr(path, img);

  RelightSession session(path);
  EXPECT_EQ(session.default_lights()[1].text, "csv:/nowhere/lamp.csv*2");
  EXPECT_TRUE(session.default_lights()[1].off);
  try {
    session.relight();
    FAIL() << "no error";
  } catch (const spectral::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("prizma:lights back"), std::string::npos) << what;
    EXPECT_NE(what.find("--light back=SPEC"), std::string::npos) << what;
  }
  session.set_light("key", "A");  // another light does not fix it
  EXPECT_THROW(session.relight(), spectral::InputError);
  session.set_light("back", "off");  // switching it off explicitly does
  EXPECT_NO_THROW(session.relight());
  const float y_key_only = session.xyz().xyz[1];
  session.set_light("back", "D65");
  EXPECT_NO_THROW(session.relight());
  EXPECT_FLOAT_EQ(session.xyz().xyz[1], 2.0f * y_key_only);  // both lights see T = 0.5, Y = 1 each
  // One spectrum for every light makes it usable too, at the scale it was recorded with (×2).
  RelightSession fresh(path);
  fresh.set_light("", "D65");
  EXPECT_EQ(fresh.settings().lights[1].text, "D65*2");
  EXPECT_NO_THROW(fresh.relight());
  EXPECT_FLOAT_EQ(fresh.xyz().xyz[1], 3.0f * y_key_only);
}

TEST(RelightSession, UnknownLightNameListsTheFilesLights) {
  const fs::path dir = spectral::test::scratch_dir("unknown");
  RelightSession session(write_fixture(dir));
  try {
    session.set_light("fill", "D65");
    FAIL() << "no error";
  } catch (const spectral::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("key, back"), std::string::npos) << e.what();
  }
  // The failed change left the session as it was.
  EXPECT_EQ(session.settings().lights[0].text, "D65");
}

TEST(RelightSession, ProbeReportsBinsXyzLabAndSrgb) {
  const fs::path dir = spectral::test::scratch_dir("probe");
  RelightSession session(write_fixture(dir));
  session.set_light("", "D65");
  const ProbeResult r = session.probe(1, 1);
  ASSERT_EQ(r.bins.size(), 2u);
  EXPECT_FLOAT_EQ(r.bins[0][5], 0.5f);
  EXPECT_FLOAT_EQ(r.bins[1][5], 0.0f);
  // A grey T = 0.5 under D65 normalised to Y = 1 is D65's white at Y = 0.5: Lab (76.07, 0, 0)
  // (L* = 116·0.5^{1/3} − 16). The bins only cover 400–700 nm, so a*, b* are near but not at 0.
  EXPECT_NEAR(r.xyz.y(), 0.5, 1e-6);
  EXPECT_NEAR(r.lab[0], 116.0 * std::cbrt(0.5) - 16.0, 1e-4);
  EXPECT_NEAR(r.lab[1], 0.0, 2.0);
  EXPECT_NEAR(r.lab[2], 0.0, 2.0);
  // sRGB of a mid grey: encode(0.5) ≈ 0.7354 in each channel (within the same chroma slack).
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(r.srgb[c], spectral::srgb_encode(0.5), 0.03);
  EXPECT_THROW(session.probe(6, 0), spectral::InputError);
}

TEST(RelightSession, CompareGivesZeroForEqualRegionsAndPositiveOtherwise) {
  const fs::path dir = spectral::test::scratch_dir("compare");
  RelightSession session(write_fixture(dir));
  EXPECT_NEAR(session.compare(0, 0, 1, 1).delta_e2000, 0.0, 1e-9);
  EXPECT_GT(session.compare(0, 0, 4, 0).delta_e2000, 5.0);
  // Region mean: a radius-1 square around (2, 1) covers columns 1–3 (two grey, one red-ish).
  const CompareResult c = session.compare(2, 1, 2, 1, 1);
  const spectral::XyzImage& img = session.xyz();
  const Eigen::Vector3d mean = (img.at(1, 0) + img.at(2, 0) + img.at(3, 0) + img.at(1, 1) + img.at(2, 1) +
                                img.at(3, 1) + img.at(1, 2) + img.at(2, 2) + img.at(3, 2)) / 9.0;
  EXPECT_NEAR((c.xyz1 - mean).norm(), 0.0, 1e-6);
}

TEST(RelightSession, ExrOutputHoldsTheXyzAndMetadata) {
  const fs::path dir = spectral::test::scratch_dir("exr");
  RelightSession session(write_fixture(dir));
  session.set_exposure(1.0);
  const fs::path out = dir / "out.exr";
  session.save(out);
  int channels = 0;
  OIIO::ImageSpec spec;
  const std::vector<float> px = read_pixels(out, channels, &spec);
  ASSERT_EQ(channels, 3);
  ASSERT_EQ(px.size(), session.xyz().xyz.size());
  for (std::size_t k = 0; k < px.size(); ++k) EXPECT_FLOAT_EQ(px[k], session.xyz().xyz[k]);
  EXPECT_EQ(spec.get_string_attribute("prizma:exposureEV"), "1");
  EXPECT_NE(spec.get_string_attribute("prizma:lights").find("A*0.5"), std::string::npos);
  EXPECT_EQ(spec.get_string_attribute("prizma:cmf"), "cie1931-2");
}

// What the shell's save and the live page's Save call: an output that is the file being relit is
// refused naming the caller's input ("save", "file"), the file left as it was (docs/errors.md).
TEST(RelightSession, SaveNeverReplacesTheFileItRelights) {
  const fs::path dir = spectral::test::scratch_dir("save_input");
  const spectral::InputRecording recording;  // as run_tool holds it in the tools
  const fs::path in = write_fixture(dir);
  RelightSession session(in);
  std::ifstream before_stream(in, std::ios::binary);
  const std::string before((std::istreambuf_iterator<char>(before_stream)), std::istreambuf_iterator<char>());
  try {
    session.save(dir / "." / "scene.exr", "file");
    FAIL() << "saved over the input";
  } catch (const spectral::InputError& e) {
    EXPECT_EQ(e.input(), "file");
    EXPECT_NE(e.reason().find("the OpenEXR file this run reads"), std::string::npos) << e.what();
  }
  std::ifstream after_stream(in, std::ios::binary);
  EXPECT_EQ(std::string((std::istreambuf_iterator<char>(after_stream)), std::istreambuf_iterator<char>()), before);
  session.save(dir / "saved.exr", "file");
  EXPECT_TRUE(fs::is_regular_file(dir / "saved.exr"));
}

TEST(InteractiveShell, ScriptedSessionThroughAStream) {
  const fs::path dir = spectral::test::scratch_dir("shell");
  RelightSession session(write_fixture(dir));
  const fs::path saved = dir / "saved.exr";
  const fs::path preview = dir / "preview.exr";
  std::istringstream script("light key off\n"
                            "light back E\n"
                            "probe 4 2\n"
                            "bogus command\n"
                            "light fill D65\n"
                            "exposure 1\n"
                            "probe 4 2\n"
                            "compare 0 0 4 0 1\n"
                            "save " + saved.string() + "\n"
                            "quit\n"
                            "probe 0 0\n");
  std::ostringstream out;
  InteractiveOptions opts;
  opts.preview = preview;
  const int failures = run_interactive(session, script, out, opts);
  const std::string text = out.str();
  EXPECT_EQ(failures, 2) << text;  // "bogus command" and "light fill"
  EXPECT_NE(text.find("error: bogus: unknown command"), std::string::npos) << text;
  EXPECT_NE(text.find("no light \"fill\""), std::string::npos) << text;
  // Probe lines: the second is at +1 EV, so its Y is twice the first.
  std::regex xyz_line(R"(XYZ (\S+) (\S+) (\S+))");
  std::vector<double> ys;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), xyz_line); it != std::sregex_iterator(); ++it)
    ys.push_back(std::stod((*it)[2]));
  ASSERT_EQ(ys.size(), 2u) << text;  // the probe after quit never ran
  EXPECT_GT(ys[0], 0.1);
  EXPECT_NEAR(ys[1], 2.0 * ys[0], 1e-5);
  // Under E with key off, pixel (4, 2) holds back's ramp: Y = Σ_i (i/11)·W_y,i (W normalised).
  const spectral::RelightMatrix e(session.image().bins, {parse_light_spec("off"), parse_light_spec("E")}, {});
  double y = 0.0;
  for (int i = 0; i < 12; ++i) y += e.light(1)(1, i) * i / 11.0;
  EXPECT_NEAR(ys[0], y, 1e-5);
  // Bins print at full float precision (back's ramp: 1/11 = 0.0909091).
  EXPECT_NE(text.find("bins back: 0 0.0909091 0.181818"), std::string::npos) << text;
  EXPECT_NE(text.find("dE2000"), std::string::npos);
  EXPECT_NE(text.find("relit in"), std::string::npos);
  // Saved file and preview both hold the final image.
  int channels = 0;
  const std::vector<float> px = read_pixels(saved, channels);
  ASSERT_EQ(px.size(), 6u * 4u * 3u);
  EXPECT_NEAR(px[3 * (2 * 6 + 4) + 1], ys[1], 1e-5);
  EXPECT_EQ(read_pixels(preview, channels), px);
}

TEST(BatchFile, WritesEveryOutputFromOneLoad) {
  const fs::path dir = spectral::test::scratch_dir("batch");
  RelightSession session(write_fixture(dir));
  std::ofstream(dir / "batch.json") << R"({
    "defaults": {"lights": {"back": "off"}},
    "outputs": [
      {"file": "d65.exr", "lights": {"key": "D65"}},
      {"file": "bright.exr", "lights": {"key": "D65"}, "exposure": 2},
      {"file": "back.exr", "lights": "F11", "cmf": "1964"},
      {"file": "all1.exr", "lights": "F11*1", "cmf": "1964"}
    ]})";
  const auto outputs = read_batch_file(dir / "batch.json", session, session.settings());
  ASSERT_EQ(outputs.size(), 4u);
  run_batch(session, outputs, nullptr);
  int ch = 0;
  const auto d65 = read_pixels(dir / "d65.exr", ch);
  const auto bright = read_pixels(dir / "bright.exr", ch);
  const auto back = read_pixels(dir / "back.exr", ch);
  ASSERT_EQ(d65.size(), 72u);
  ASSERT_EQ(bright.size(), 72u);
  ASSERT_EQ(back.size(), 72u);
  EXPECT_NEAR(d65[1], 0.5, 1e-6);            // grey under key
  EXPECT_EQ(d65[3 * 4 + 1], 0.0f);           // back is off in the defaults
  EXPECT_NEAR(bright[1], 4.0 * d65[1], 1e-6);
  // "F11" for every light keeps each light's scale: back, off in the defaults, stays off; "F11*1"
  // puts every light at scale 1 and lights the right half (relight.md, "One spectrum for every light").
  EXPECT_EQ(back[3 * 4 + 1], 0.0f);
  EXPECT_GT(back[1], 0.05f);
  const auto all1 = read_pixels(dir / "all1.exr", ch);
  EXPECT_GT(all1[3 * 4 + 1], 0.05f);
  EXPECT_EQ(all1[1], back[1]);
}

TEST(RelightSession, OneSpectrumForEveryLightKeepsEachLightsScale) {
  // The scale a light has (recorded, or set before) is kept by a spec without one; a spec with one is
  // used as it is; a light that is off stays off (issue 25 item 5).
  const fs::path dir = spectral::test::scratch_dir("every-light");
  RelightSession session(write_fixture(dir));
  session.set_light("key", "D65*0.25");
  session.set_light("", "F11");
  EXPECT_EQ(session.settings().lights[0].text, "F11*0.25");
  EXPECT_EQ(session.settings().lights[0].scale, 0.25);
  EXPECT_FALSE(session.settings().lights[0].off);
  session.set_light("back", "off");
  session.set_light("", "A");
  EXPECT_TRUE(session.settings().lights[1].off);
  EXPECT_EQ(session.settings().lights[1].text, "off");
  EXPECT_EQ(session.settings().lights[0].text, "A*0.25");
  session.set_light("", "A*2");
  EXPECT_EQ(session.settings().lights[0].text, "A*2");
  EXPECT_EQ(session.settings().lights[1].text, "A*2");
  EXPECT_FALSE(session.settings().lights[1].off);
  // The weights follow the texts: "F11" at key's 0.25 is a quarter of F11 at scale 1.
  session.set_light("key", "D65*0.25");
  session.set_light("", "F11");
  const Eigen::MatrixXd quarter = session.matrix().light(0);
  session.set_light("key", "F11");
  EXPECT_TRUE(quarter.isApprox(0.25 * session.matrix().light(0), 1e-12));
}

TEST(BatchFile, BadEntryStopsTheBatchBeforeAnythingIsWritten) {
  const fs::path dir = spectral::test::scratch_dir("batchbad");
  RelightSession session(write_fixture(dir));
  std::ofstream(dir / "batch.json") << R"({"outputs": [
      {"file": "first.exr"},
      {"file": "second.exr", "lights": {"fill": "D65"}}]})";
  try {
    read_batch_file(dir / "batch.json", session, session.settings());
    FAIL() << "no error";
  } catch (const spectral::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("outputs[1].lights"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "first.exr"));
  std::ofstream(dir / "typo.json") << R"({"outputs": [{"file": "a.exr", "exposre": 1}]})";
  EXPECT_THROW(read_batch_file(dir / "typo.json", session, session.settings()), spectral::InputError);
  std::ofstream(dir / "format.json") << R"({"outputs": [{"file": "a.bmp"}]})";
  EXPECT_THROW(read_batch_file(dir / "format.json", session, session.settings()), spectral::InputError);
}

// issue 11: a batch bitDepth of 8.7 or 4294967304 became 8; deeply nested JSON crashed.
TEST(BatchFile, RefusesNonIntegerBitDepthsAndDeepJson) {
  const fs::path dir = spectral::test::scratch_dir("batchdepth");
  RelightSession session(write_fixture(dir));
  auto error = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    try {
      read_batch_file(dir / name, session, session.settings());
    } catch (const spectral::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  for (const char* bad : {"8.7", "4294967304", "24", "\"8\"", "-8"}) {
    const std::string msg = error("bits.json", std::string(R"({"outputs": [{"file": "a.png", "bitDepth": )") + bad + "}]}");
    EXPECT_NE(msg.find("outputs[0].bitDepth: must be 8 or 16"), std::string::npos) << bad << ": " << msg;
  }
  EXPECT_EQ(error("ok.json", R"({"outputs": [{"file": "a.png", "bitDepth": 16}]})"), "no error");
  const std::string deep = error("deep.json", R"({"outputs": [{"file": "a.png", "view": )" + std::string(70000, '[') +
                                                  std::string(70000, ']') + "}]}");
  EXPECT_NE(deep.find("nested deeper than"), std::string::npos) << deep;
}

TEST(OutputImage, RejectsUnwritableAndUnknownPaths) {
  const fs::path dir = spectral::test::scratch_dir("paths");
  EXPECT_THROW(spectral::check_output_path(dir / "missing" / "a.png"), spectral::InputError);
  EXPECT_THROW(spectral::check_output_path(dir / "a.gif"), spectral::InputError);  // .jpg is written since JPEG output
  EXPECT_NO_THROW(spectral::check_output_path(dir / "a.jpg"));
  EXPECT_THROW(spectral::check_output_path(dir), spectral::InputError);
  EXPECT_NO_THROW(spectral::check_output_path(dir / "a.png"));
}

}  // namespace
}  // namespace prizma::relight
