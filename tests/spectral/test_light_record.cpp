// prizma:lights records (light_record.h): parse ⇄ write, type errors, the default-light rule.
#include "prizma/spectral/light_record.h"

#include <gtest/gtest.h>

#include "prizma/spectral/error.h"

namespace {

using namespace prizma::spectral;

std::string error_of(std::string_view text) {
  try {
    parse_light_records(text, "f.exr: prizma:lights");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(LightRecord, RendererRecordsReadBackAndPrintAsBefore) {
  // The text a render of the default scene and a spot-lit scene wrote before records were typed
  // (keys in alphabetical order, numbers as nlohmann prints doubles).
  const std::string text =
      R"([{"angularSizeDeg":0.5,"direction":[-1.0,0.0,1.0],"name":"side","spectrum":"D65"},)"
      R"({"angularSizeDeg":0.0,"direction":[0.0,0.0,0.0],"name":"spot","position":[0.0,1.0,0.0],"radius":0.25,)"
      R"("spectrum":"A*0.5","spot":{"coneDeg":30.0,"direction":[0.0,-1.0,0.0],"falloffDeg":5.0}},)"
      R"({"angularSizeDeg":0.0,"direction":[0.0,0.0,0.0],"environment":"sky.exr","name":"sky","rotationDeg":90.0,"spectrum":"D65*0.2"},)"
      R"({"angularSizeDeg":0.0,"direction":[0.0,0.0,0.0],"emission":true,"name":"glow","spectrum":"E"}])";
  const std::vector<LightRecord> r = parse_light_records(text, "t");
  ASSERT_EQ(r.size(), 4u);
  EXPECT_EQ(r[0].name, "side");
  EXPECT_EQ(r[0].direction, (std::array<double, 3>{-1, 0, 1}));
  EXPECT_EQ(r[0].angular_size_deg, 0.5);
  EXPECT_FALSE(r[0].position.has_value());
  ASSERT_TRUE(r[1].spot.has_value());
  EXPECT_EQ(r[1].spot->cone_deg, 30.0);
  EXPECT_EQ(r[1].spot->falloff_deg, 5.0);
  EXPECT_EQ(r[1].radius, 0.25);
  EXPECT_EQ(r[2].environment, std::optional<std::string>("sky.exr"));
  EXPECT_EQ(r[2].rotation_deg, 90.0);
  EXPECT_TRUE(r[3].emission);
  EXPECT_FALSE(r[2].emission);
  EXPECT_EQ(light_records_json(r), text);
}

TEST(LightRecord, OnlyTheFieldsThatAreSetAreWritten) {
  EXPECT_EQ(light_records_json({light_record("a", "D65"), light_record("b")}),
            R"([{"name":"a","spectrum":"D65"},{"name":"b"}])");
  EXPECT_EQ(light_records_json(light_records_for({"key", "fill"})), R"([{"name":"key"},{"name":"fill"}])");
  EXPECT_EQ(light_records_json({}), "[]");
}

TEST(LightRecord, RefusesWhatItCannotRead) {
  EXPECT_EQ(error_of("[{not json"), "f.exr: prizma:lights: is not valid JSON");
  EXPECT_EQ(error_of(R"({"name":"a"})"), "f.exr: prizma:lights: is not a JSON array of lights");
  EXPECT_EQ(error_of(R"([{"name":"a"}, 3])"), "f.exr: prizma:lights[1]: is not an object");
  EXPECT_EQ(error_of(R"([{"spectrum":"D65"}])"), "f.exr: prizma:lights[0]: has no \"name\"");
  EXPECT_EQ(error_of(R"([{"name":7}])"), "f.exr: prizma:lights[0]: \"name\" must be a string");
  EXPECT_EQ(error_of(R"([{"name":"a","spectrum":1}])"), "f.exr: prizma:lights[0]: \"spectrum\" must be a string");
  EXPECT_EQ(error_of(R"([{"name":"a","direction":[1,2]}])"),
            "f.exr: prizma:lights[0]: \"direction\" must be an array of 3 numbers");
  EXPECT_EQ(error_of(R"([{"name":"a","emission":"yes"}])"), "f.exr: prizma:lights[0]: \"emission\" must be true or false");
  EXPECT_EQ(error_of(R"([{"name":"a","spot":{"coneDeg":"wide"}}])"),
            "f.exr: prizma:lights[0].spot: \"coneDeg\" must be a number");
  EXPECT_NE(error_of(std::string(200, '[') + std::string(200, ']')).find("JSON nested deeper than"), std::string::npos);
  // Unknown fields are ignored (a later version may add some).
  EXPECT_EQ(error_of(R"([{"name":"a","colour":"red"}])"), "");
}

TEST(LightRecord, RecordsMustDescribeTheLayers) {
  const auto check = [](std::vector<LightRecord> r, std::vector<std::string> layers) {
    try {
      check_light_records(r, layers, "f.exr");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(check(light_records_for({"key", "back"}), {"key"}),
            "f.exr: prizma:lights announces light \"back\" but the file has no layer for it (layers: key)");
  EXPECT_EQ(check(light_records_for({"key", "key"}), {"key"}), "f.exr: prizma:lights records light \"key\" twice");
  EXPECT_EQ(check(light_records_for({"sun"}), {"default"}), "");  // one light: the layer whatever its name
  EXPECT_EQ(check({}, {"a", "b"}), "");
  EXPECT_EQ(check(light_records_for({"b", "a"}), {"a", "b", "c"}), "");  // c records nothing: D65
}

TEST(LightRecord, DefaultSpectrumRule) {
  const std::vector<LightRecord> two = {light_record("key", "A"), light_record("sky", "D65*0.2")};
  EXPECT_EQ(default_spectrum(two, "sky", 2), "D65*0.2");
  EXPECT_EQ(default_spectrum(two, "key", 3), "A");
  EXPECT_EQ(default_spectrum(two, "other", 3), "D65");
  // One layer, one record: that record's spectrum whatever the names (a one-light render's layer is
  // the top level, read back as the record's name or "default").
  EXPECT_EQ(default_spectrum({light_record("sun", "F11")}, "default", 1), "F11");
  EXPECT_EQ(default_spectrum({light_record("sun")}, "sun", 1), "D65");  // nothing recorded
  EXPECT_EQ(default_spectrum({}, "sun", 1), "D65");
}

}  // namespace
