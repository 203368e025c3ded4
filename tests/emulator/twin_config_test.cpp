// Twin config: defaults, overlay, errors naming the key, the shipped file equal to the defaults.
#include "emulator/twin_config_schema.hpp"

#include <gtest/gtest.h>
#include "drivers/json.hpp"

#include <fstream>

namespace synbench::emulator {
namespace {

std::string error_key(const synbench::Json& doc) {
  TwinConfig c;
  try {
    apply_json(c, doc);
  } catch (const ConfigError& e) {
    return e.pointer() + " | " + e.reason();
  }
  return "no error";
}

TEST(TwinConfig, PartialOverlayChangesOnlyTheNamedKeys) {
  TwinConfig c;
  apply_json(c, synbench::Json::parse(R"({"synrm": {"rs_ohm": 10.5}, "vfc": {"motor": {"gain_error": 0.01}}})"));
  EXPECT_DOUBLE_EQ(c.synrm.rs_ohm, 10.5);
  EXPECT_DOUBLE_EQ(c.vfc.motor.gain_error, 0.01);
  EXPECT_DOUBLE_EQ(c.synrm.flux_d.l0_H, 0.670);
}

TEST(TwinConfig, ErrorsNameTheKeyAndTheReason) {
  EXPECT_EQ(error_key(synbench::Json::parse(R"({"synrm": {"rs_ohms": 1}})")), "/synrm/rs_ohms | unknown field");
  EXPECT_EQ(error_key(synbench::Json::parse(R"({"synrm": {"rs_ohm": "9"}})")), "/synrm/rs_ohm | must be a finite number");
  EXPECT_EQ(error_key(synbench::Json::parse(R"({"synrm": {"rs_ohm": -1}})")), "/synrm/rs_ohm | -1 is outside (0, inf]");
  EXPECT_EQ(error_key(synbench::Json::parse(R"({"synrm": {"pole_pairs": 2.5}})")), "/synrm/pole_pairs | must be an integer in 1..32");
  EXPECT_EQ(error_key(synbench::Json::parse(R"({"firmware": {"pwm": "spwm"}})")),
            "/firmware/pwm | unknown pwm 'spwm' (expected capwm, aspwm)");
  EXPECT_EQ(error_key(synbench::Json::parse(R"({"inverter": {"dead_time_compensation": 1}})")),
            "/inverter/dead_time_compensation | must be true or false");
  EXPECT_EQ(error_key(synbench::Json::parse(R"({"dc_bus": {"brake_off_V": 445}})")),
            "/dc_bus/brake_off_V | must be below dc_bus.brake_on_V");
  EXPECT_EQ(error_key(synbench::Json::parse(R"({"nonsense": {}})")), "/nonsense | unknown field");
  EXPECT_EQ(error_key(synbench::Json::parse(R"([1, 2])")), " | the document must be a JSON object");
  // Comments (keys starting with '_') are allowed anywhere.
  EXPECT_EQ(error_key(synbench::Json::parse(R"({"_note": "x", "synrm": {"_assumed": ["b2"]}})")), "no error");
}

TEST(TwinConfig, DefaultsRoundTripThroughJsonAndMarkAssumedValues) {
  const auto j = to_json(TwinConfig{});
  TwinConfig c;
  c.synrm.rs_ohm = 1;
  apply_json(c, j);
  EXPECT_EQ(to_json(c), j);
  const auto& assumed = j["synrm"]["_assumed"];
  EXPECT_NE(std::find(assumed.begin(), assumed.end(), "b2_Nms2_per_rad2"), assumed.end());
  EXPECT_EQ(std::find(assumed.begin(), assumed.end(), "rs_ohm"), assumed.end());
}

TEST(TwinConfig, ShippedConfigFileEqualsTheDefaults) {
  std::ifstream in(std::string(SYNBENCH_SOURCE_DIR) + "/config/twin.json");
  ASSERT_TRUE(in) << "config/twin.json missing: regenerate with `synbench config --defaults`";
  EXPECT_EQ(synbench::Json::parse(in), to_json(TwinConfig{}))
      << "regenerate config/twin.json with `synbench config --defaults`";
}

TEST(TwinConfig, BusScalingMovesChopperAndTrips) {
  TwinConfig c;
  c.scale_bus_to(560.0);
  EXPECT_DOUBLE_EQ(c.dc_bus.source_V, 560.0);
  EXPECT_NEAR(c.dc_bus.brake_on_V, 440.0 * 560 / 425, 1e-9);
  EXPECT_NEAR(c.firmware.overvoltage_trip_V, 450.0 * 560 / 425, 1e-9);
  EXPECT_NO_THROW(validate(c));
}

}  // namespace
}  // namespace synbench::emulator

namespace synbench::emulator {
namespace {

TEST(TwinConfig, DocumentedTableIsTheGeneratedOne) {
  std::ifstream in(std::string(SYNBENCH_SOURCE_DIR) + "/docs/emulator-config.md");
  ASSERT_TRUE(in);
  const std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string begin = "<!-- generated: synbench config --markdown -->\n";
  const auto a = doc.find(begin), b = doc.find("<!-- end generated -->");
  ASSERT_NE(a, std::string::npos);
  ASSERT_NE(b, std::string::npos);
  EXPECT_EQ(doc.substr(a + begin.size(), b - a - begin.size()), markdown_reference(TwinConfig{}))
      << "regenerate the table in docs/emulator-config.md with `synbench config --markdown`";
}

}  // namespace
}  // namespace synbench::emulator
