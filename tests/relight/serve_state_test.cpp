// The live page's state strings (serve_state.h): parsed by the command line's parsers, refused with
// the key named, and written back canonically.
#include <gtest/gtest.h>

#include "prizma/relight/serve_state.h"
#include "prizma/spectral/error.h"
#include "spectral/relight_test_util.h"

namespace prizma::relight {
namespace {

RelightSession make_session() {
  auto img = spectral::test::make_image(2, 2, spectral::BinLayout::linear(400.0, 700.0, 6), {"side", "back"},
                              [](int, int, int) { return 0.5f; });
  img.info.light_records = prizma::spectral::parse_light_records(R"([{"name":"side","spectrum":"D65"},{"name":"back","spectrum":"A*0.5"}])", "test");
  return RelightSession(std::move(img), "mem.exr");
}

TEST(ServeState, AppliesEveryKey) {
  RelightSession s = make_session();
  const RelightSettings out = settings_from_state(
      {{"light.side", "F11*2"}, {"light.back", "off"}, {"exposure", "-1.5"}, {"cmf", "2012-10"},
       {"display", "Display P3"}, {"adapt", "1"}},
      s, s.settings());
  EXPECT_EQ(out.lights[0].text, "F11*2");
  EXPECT_DOUBLE_EQ(out.lights[0].scale, 2.0);
  EXPECT_TRUE(out.lights[1].off);
  EXPECT_DOUBLE_EQ(out.relight.exposure_ev, -1.5);
  EXPECT_EQ(out.relight.cmf, spectral::Observer::Cie2012_10deg);
  EXPECT_EQ(out.output.display.display, "Display P3");
  EXPECT_TRUE(out.relight.adapt_to_d65);
}

TEST(ServeState, MissingKeysKeepTheBase) {
  RelightSession s = make_session();
  const RelightSettings out = settings_from_state({{"exposure", "2"}}, s, s.settings());
  EXPECT_EQ(out.lights[1].text, "A*0.5");
  EXPECT_EQ(out.relight.cmf, spectral::Observer::Cie1931_2deg);
}

TEST(ServeState, RefusesBadInputNamingTheKey) {
  RelightSession s = make_session();
  const auto fails = [&](const char* key, const char* value, const char* expected) {
    try {
      settings_from_state({{key, value}}, s, s.settings());
      ADD_FAILURE() << key << "=" << value << " was accepted";
    } catch (const spectral::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  fails("light.fill", "D65", "no light \"fill\"");
  fails("light.side", "D66", "D66");
  fails("light.side", "csv:/etc/passwd", "csv: spectra are not read from the page");
  fails("exposure", "1e9", "±64");
  fails("exposure", "nan", "not a number");
  fails("exposure", "1x", "not a number");
  fails("cmf", "1955", "state: cmf");
  fails("adapt", "maybe", "expected 0 or 1");
  fails("colour", "red", "unknown key");
}

TEST(ServeState, WritesTheCanonicalString) {
  RelightSession s = make_session();
  RelightSettings in = settings_from_state({{"light.side", "gaussian:550:20*0.5"}, {"exposure", "0.1"},
                                            {"display", "Display P3"}},
                                           s, s.settings());
  EXPECT_EQ(state_string(in, s),
            "light.side=gaussian:550:20*0.5&light.back=A*0.5&exposure=0.1&cmf=1931&display=Display%20P3&adapt=0");
  // And it reads back to the same settings.
  const RelightSettings again = settings_from_state(
      {{"light.side", "gaussian:550:20*0.5"}, {"light.back", "A*0.5"}, {"exposure", "0.1"}, {"cmf", "1931"},
       {"display", "Display P3"}, {"adapt", "0"}},
      s, s.settings());
  EXPECT_EQ(state_string(again, s), state_string(in, s));
}

TEST(ServeState, UrlEncodesReservedCharacters) {
  EXPECT_EQ(url_encode("a b&c=d/é"), "a%20b%26c%3Dd%2F%C3%A9");
  EXPECT_EQ(url_encode("blackbody:3200K*0.5"), "blackbody:3200K*0.5");
}

}  // namespace
}  // namespace prizma::relight
