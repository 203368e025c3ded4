// Tests of device-profile validation: each mistake is rejected once, at its exact JSON pointer;
// and the defaults a profile may leave out.
#include "drivers/profile/device_profile.hpp"
#include "drivers/error.hpp"

#include <gtest/gtest.h>
#include "drivers/json.hpp"

#include <cmath>
#include <fstream>
#include <functional>
#include <string>

namespace synbench::drivers {
namespace {

using json = synbench::Json;

json default_doc(DeviceKind kind) {
  std::ifstream in(default_profile_path(kind));
  return json::parse(in);
}

std::string describe(const std::vector<ProfileError>& errors) {
  std::string s;
  for (const ProfileError& e : errors) s += "\n  '" + e.pointer + "': " + e.reason;
  return s;
}

struct InvalidCase {
  std::string name;
  DeviceKind base;
  std::function<void(json&)> mutate;
  std::string path;
  std::string reason_contains;
};

const std::vector<InvalidCase> kInvalid = {
    {"unknown_type", DeviceKind::vfc_meter, [](json& d) { d["signals"]["gate_s"]["type"] = "f64"; },
     "/signals/gate_s/type", "unknown type 'f64'"},
    {"bool_type_on_a_register", DeviceKind::vfc_meter, [](json& d) { d["signals"]["gate_s"]["type"] = "bool"; },
     "/signals/gate_s/type", "bool is for coils"},
    {"register_type_on_a_coil", DeviceKind::vfc_meter, [](json& d) { d["signals"]["gate_start"]["type"] = "u16"; },
     "/signals/gate_start/type", "carries type bool"},
    {"missing_type", DeviceKind::vfc_meter, [](json& d) { d["signals"]["gate_s"].erase("type"); },
     "/signals/gate_s/type", "required"},
    {"unknown_register_kind", DeviceKind::vfc_meter,
     [](json& d) { d["signals"]["gate_s"]["register"] = "holdings"; }, "/signals/gate_s/register",
     "unknown register kind 'holdings'"},
    {"overlap_same_kind_and_unit", DeviceKind::vfc_meter,
     // counts_m occupies input 102-103; counts_g moved onto 103 collides with its low word.
     [](json& d) { d["signals"]["counts_g"]["address"] = 103; }, "/signals/counts_g/address",
     "overlaps 'counts_m' (input 102..103, unit id 3)"},
    {"address_out_of_range", DeviceKind::vfc_meter, [](json& d) { d["signals"]["gate_s"]["address"] = 65536; },
     "/signals/gate_s/address", "65536 is outside 0..65535"},
    {"negative_address", DeviceKind::vfc_meter, [](json& d) { d["signals"]["gate_s"]["address"] = -1; },
     "/signals/gate_s/address", "outside 0..65535"},
    {"fractional_address", DeviceKind::vfc_meter, [](json& d) { d["signals"]["gate_s"]["address"] = 1.5; },
     "/signals/gate_s/address", "must be an integer"},
    {"width_past_last_address", DeviceKind::vfc_meter, [](json& d) { d["signals"]["gate_s"]["address"] = 65535; },
     "/signals/gate_s/address", "needs 2 registers"},
    {"write_access_on_input_register", DeviceKind::vfc_meter,
     [](json& d) { d["signals"]["gate_s"]["access"] = "rw"; }, "/signals/gate_s/access",
     "an input register is read-only"},
    {"write_access_on_discrete_input", DeviceKind::synrm_drive,
     [](json& d) { d["signals"]["voltage_limited"]["access"] = "w"; }, "/signals/voltage_limited/access",
     "a discrete input is read-only"},
    {"command_in_a_read_only_table", DeviceKind::vfc_meter,
     [](json& d) { d["signals"]["gate_length_ms"]["register"] = "input"; }, "/signals/gate_length_ms/register",
     "need a coil or holding register"},
    {"command_without_write_access", DeviceKind::vfc_meter,
     [](json& d) { d["signals"]["gate_start"]["access"] = "r"; }, "/signals/gate_start/access", "use w or rw"},
    {"telemetry_without_read_access", DeviceKind::vfc_meter,
     [](json& d) {
       d["signals"]["gate_s"]["register"] = "holding";
       d["signals"]["gate_s"]["access"] = "w";
     },
     "/signals/gate_s/access", "use r or rw"},
    {"unknown_access", DeviceKind::vfc_meter, [](json& d) { d["signals"]["gate_start"]["access"] = "write"; },
     "/signals/gate_start/access", "unknown access 'write'"},
    {"min_above_max", DeviceKind::vfc_meter,
     [](json& d) {
       d["signals"]["gate_s"]["min"] = 10;
       d["signals"]["gate_s"]["max"] = 1;
     },
     "/signals/gate_s/min", "min 10 exceeds max 1"},
    {"zero_scale", DeviceKind::vfc_meter, [](json& d) { d["signals"]["gate_s"]["scale"] = 0; },
     "/signals/gate_s/scale", "must not be zero"},
    {"scale_not_a_number", DeviceKind::vfc_meter, [](json& d) { d["signals"]["gate_s"]["scale"] = "0.1"; },
     "/signals/gate_s/scale", "must be a finite number"},
    {"limit_beyond_the_raw_type", DeviceKind::vfc_meter,
     [](json& d) { d["signals"]["gate_sequence"]["max"] = 70000; }, "/signals/gate_sequence/max",
     "70000 is beyond what u16 with scale 1 and offset 0 can carry"},
    {"limit_beyond_the_scaled_raw_type", DeviceKind::synrm_drive,
     [](json& d) { d["signals"]["angle_setpoint_deg"]["max"] = 360; }, "/signals/angle_setpoint_deg/max",
     "360 is beyond what i16 with scale 0.01"},
    {"writable_register_without_max", DeviceKind::vfc_meter,
     [](json& d) { d["signals"]["gate_length_ms"].erase("max"); }, "/signals/gate_length_ms/max",
     "required for a register the bench may write"},
    {"word_order_on_a_16_bit_type", DeviceKind::vfc_meter,
     [](json& d) { d["signals"]["gate_sequence"]["word_order"] = "little"; }, "/signals/gate_sequence/word_order",
     "applies to 32-bit types only"},
    {"physical_signal_on_a_bit", DeviceKind::vfc_meter,
     [](json& d) { d["signals"]["idcm_A"] = {{"register", "discrete_input"}, {"address", 7}}; },
     "/signals/idcm_A/register", "idcm_A is in A"},
    {"scale_on_a_coil", DeviceKind::vfc_meter, [](json& d) { d["signals"]["gate_start"]["scale"] = 2; },
     "/signals/gate_start/scale", "does not apply to a coil"},
    {"unit_mismatch", DeviceKind::vfc_meter, [](json& d) { d["signals"]["gate_s"]["unit"] = "ms"; },
     "/signals/gate_s/unit", "must be 's'"},
    {"missing_required_signal", DeviceKind::vfc_meter, [](json& d) { d["signals"].erase("counts_g"); },
     "/signals/counts_g", "required for meter gate"},
    {"drive_without_heartbeat_or_watchdog", DeviceKind::load_drive, [](json& d) { d["signals"].erase("heartbeat"); },
     "/watchdog", "required when the profile maps no heartbeat signal"},
    {"unknown_signal", DeviceKind::vfc_meter,
     [](json& d) { d["signals"]["speed_rpm"] = d["signals"]["gate_s"]; }, "/signals/speed_rpm",
     "unknown signal for kind vfc_meter"},
    {"signal_name_escaped_in_pointer", DeviceKind::vfc_meter,
     [](json& d) { d["signals"]["idc/m~A"] = d["signals"]["gate_s"]; }, "/signals/idc~1m~0A",
     "unknown signal"},
    {"unknown_signal_field", DeviceKind::vfc_meter, [](json& d) { d["signals"]["gate_s"]["scael"] = 2; },
     "/signals/gate_s/scael", "unknown field"},
    {"unknown_top_level_field", DeviceKind::vfc_meter, [](json& d) { d["unitid"] = 3; }, "/unitid",
     "unknown field"},
    {"device_unit_id_zero", DeviceKind::vfc_meter, [](json& d) { d["unit_id"] = 0; }, "/unit_id",
     "0 is outside 1..247"},
    {"signal_unit_id_248", DeviceKind::vfc_meter, [](json& d) { d["signals"]["gate_s"]["unit_id"] = 248; },
     "/signals/gate_s/unit_id", "248 is outside 1..247"},
    {"missing_unit_id", DeviceKind::vfc_meter, [](json& d) { d.erase("unit_id"); }, "/unit_id", "required"},
    {"unknown_device_kind", DeviceKind::vfc_meter, [](json& d) { d["kind"] = "power_meter"; }, "/kind",
     "unknown device kind 'power_meter'"},
    {"missing_name", DeviceKind::vfc_meter, [](json& d) { d.erase("name"); }, "/name", "required"},
    {"missing_signals", DeviceKind::vfc_meter, [](json& d) { d.erase("signals"); }, "/signals", "required"},
    {"signal_not_an_object", DeviceKind::vfc_meter, [](json& d) { d["signals"]["gate_s"] = 106; },
     "/signals/gate_s", "must be an object"},
    {"unknown_device_byte_order", DeviceKind::vfc_meter, [](json& d) { d["byte_order"] = "middle"; },
     "/byte_order", "unknown byte order 'middle'"},
    {"unknown_signal_word_order", DeviceKind::vfc_meter,
     [](json& d) { d["signals"]["counts_m"]["word_order"] = "swapped"; }, "/signals/counts_m/word_order",
     "unknown word order 'swapped'"},
    {"enum_value_outside_limits", DeviceKind::vfc_meter,
     [](json& d) { d["signals"]["gate_status"]["values"]["done"] = 7; }, "/signals/gate_status/values/done",
     "7 is outside the signal's limits"},
    {"enum_label_unknown", DeviceKind::vfc_meter,
     [](json& d) { d["signals"]["gate_status"]["values"]["closed"] = 2; }, "/signals/gate_status/values/closed",
     "unknown label for gate_status (expected idle, open, done)"},
    {"enum_on_a_signal_without_labels", DeviceKind::vfc_meter,
     [](json& d) { d["signals"]["gate_sequence"]["values"] = {{"first", 0}}; }, "/signals/gate_sequence/values",
     "gate_sequence is not an enumerated signal"},
    {"enum_value_twice", DeviceKind::vfc_meter,
     [](json& d) { d["signals"]["gate_status"]["values"]["open"] = 2; }, "/signals/gate_status/values/done",
     "also a code of 'open'"},
    {"enum_on_a_float", DeviceKind::vfc_meter,
     [](json& d) {
       d["signals"]["gate_status"]["type"] = "f32";
       d["signals"]["gate_status"]["address"] = 120;
     },
     "/signals/gate_status/values", "needs an integer type"},
    {"heartbeat_timeout_not_above_period", DeviceKind::load_drive,
     [](json& d) { d["signals"]["heartbeat"]["timeout_ms"] = 100; }, "/signals/heartbeat/timeout_ms",
     "must exceed period_ms (100)"},
    {"heartbeat_without_period", DeviceKind::load_drive,
     [](json& d) { d["signals"]["heartbeat"].erase("period_ms"); }, "/signals/heartbeat/period_ms", "required"},
    // A drive's documented stop time (the safety supervisor waits for its ramp that long).
    {"stop_time_on_a_meter", DeviceKind::vfc_meter, [](json& d) { d["stop_time_ms"] = 100; }, "/stop_time_ms",
     "applies to drives only"},
    {"stop_time_above_a_minute", DeviceKind::synrm_drive, [](json& d) { d["stop_time_ms"] = 60001; }, "/stop_time_ms",
     "60001 is outside 0..60000"},
    {"stop_time_in_seconds", DeviceKind::load_drive, [](json& d) { d["stop_time_ms"] = 1.5; }, "/stop_time_ms",
     "must be an integer"},
    {"period_on_another_signal", DeviceKind::vfc_meter, [](json& d) { d["signals"]["gate_s"]["period_ms"] = 100; },
     "/signals/gate_s/period_ms", "heartbeat signal only"},
    // Array signals ("count"): the catalogue's batch arrays need one, any other signal refuses it.
    {"array_without_count", DeviceKind::vfc_meter, [](json& d) { d["signals"]["batch_counts_m"].erase("count"); },
     "/signals/batch_counts_m/count", "required: batch_counts_m is an array of 2..64"},
    {"count_on_a_single_value", DeviceKind::vfc_meter, [](json& d) { d["signals"]["gate_s"]["count"] = 4; },
     "/signals/gate_s/count", "gate_s is a single value; count applies to array signals only"},
    {"count_below_two", DeviceKind::load_drive, [](json& d) { d["signals"]["window_batch_torque_Nm"]["count"] = 1; },
     "/signals/window_batch_torque_Nm/count", "1 is outside 2..64"},
    {"count_above_64", DeviceKind::synrm_drive, [](json& d) { d["signals"]["window_batch_im_A"]["count"] = 65; },
     "/signals/window_batch_im_A/count", "65 is outside 2..64"},
    {"count_not_an_integer", DeviceKind::synrm_drive, [](json& d) { d["signals"]["window_batch_im_A"]["count"] = "10"; },
     "/signals/window_batch_im_A/count", "must be an integer"},
    {"array_with_a_mask", DeviceKind::vfc_meter,
     [](json& d) {
       d["signals"]["batch_counts_m"]["type"] = "u16";
       d["signals"]["batch_counts_m"]["max"] = 1;
       d["signals"]["batch_counts_m"]["bit"] = 3;
     },
     "/signals/batch_counts_m/bit", "does not apply to an array"},
    // The overlap check sees the whole array: u32 x 10 at 112 runs to 131.
    {"overlap_with_an_arrays_last_value", DeviceKind::vfc_meter,
     [](json& d) { d["signals"]["batch_counts_g"]["address"] = 131; }, "/signals/batch_counts_g/address",
     "overlaps 'batch_counts_m' (input 112..131, unit id 3)"},
    {"array_past_last_address", DeviceKind::vfc_meter,
     [](json& d) { d["signals"]["batch_counts_g"]["address"] = 65530; }, "/signals/batch_counts_g/address",
     "u32 x 10 at 65530 needs 20 registers and runs past 65535"},
};

class InvalidProfile : public testing::TestWithParam<InvalidCase> {};

TEST_P(InvalidProfile, IsRejectedOnceAtItsJsonPointer) {
  const InvalidCase& c = GetParam();
  json doc = default_doc(c.base);
  c.mutate(doc);
  const ProfileParseResult r = parse_device_profile(doc);
  EXPECT_FALSE(r.profile.has_value());
  ASSERT_EQ(r.errors.size(), 1u) << describe(r.errors);
  EXPECT_EQ(r.errors[0].pointer, c.path) << describe(r.errors);
  EXPECT_NE(r.errors[0].reason.find(c.reason_contains), std::string::npos) << describe(r.errors);
}

INSTANTIATE_TEST_SUITE_P(EachMistake, InvalidProfile, testing::ValuesIn(kInvalid),
                         [](const testing::TestParamInfo<InvalidCase>& i) { return i.param.name; });

TEST(DeviceProfile, ReportsEveryProblemInOnePass) {
  json doc = default_doc(DeviceKind::vfc_meter);
  doc["signals"]["gate_s"]["type"] = "f64";
  doc["signals"]["idcm_A"]["scale"] = 0;
  doc["signals"].erase("counts_g");
  const ProfileParseResult r = parse_device_profile(doc);
  ASSERT_EQ(r.errors.size(), 3u) << describe(r.errors);
  EXPECT_EQ(r.errors[0].pointer, "/signals/gate_s/type");
  EXPECT_EQ(r.errors[1].pointer, "/signals/idcm_A/scale");
  EXPECT_EQ(r.errors[2].pointer, "/signals/counts_g");
}

TEST(DeviceProfile, NotAnObject) {
  const ProfileParseResult r = parse_device_profile(json::array());
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].pointer, "");
}

// The smallest valid vfc_meter profile, written out so the defaults below are visible.
json minimal_meter() {
  return json::parse(R"({
    "name": "third-party meter", "kind": "vfc_meter", "unit_id": 9,
    "word_order": "little", "byte_order": "little",
    "signals": {
      "_comment": "keys starting with an underscore are comments",
      "gate_start":     { "register": "coil", "address": 0 },
      "gate_length_ms": { "register": "holding", "address": 0, "type": "u32", "min": 1, "max": 1000 },
      "gate_status":    { "register": "input", "address": 0, "type": "u16", "byte_order": "big" },
      "gate_sequence":  { "register": "input", "address": 1, "type": "u16" },
      "counts_m":       { "register": "input", "address": 2, "type": "u32", "word_order": "big" },
      "counts_g":       { "register": "input", "address": 2, "type": "u32", "unit_id": 10 },
      "gate_s":         { "register": "holding", "address": 2, "type": "i32", "scale": 0.001, "access": "r" },
      "idcm_A":         { "register": "input", "address": 4, "type": "i16", "scale": 0.01, "offset": -1 },
      "idcg_A":         { "register": "input", "address": 5, "type": "f32" }
    }
  })");
}

// A drive's documented stop time reaches the device the safety supervisor asks.
TEST(DeviceProfile, AStopTimeIsTheDrivesDocumentedOne) {
  json doc = default_doc(DeviceKind::synrm_drive);
  ProfileParseResult r = parse_device_profile(doc);
  ASSERT_TRUE(r.profile) << describe(r.errors);
  EXPECT_EQ(r.profile->stop_time_ms, 0u) << "synbench's firmware stops at once";
  doc["stop_time_ms"] = 2500;
  r = parse_device_profile(doc);
  ASSERT_TRUE(r.profile) << describe(r.errors);
  EXPECT_EQ(r.profile->stop_time_ms, 2500u);
}

TEST(DeviceProfile, DefaultsOfAMinimalProfile) {
  const ProfileParseResult r = parse_device_profile(minimal_meter());
  ASSERT_TRUE(r.profile) << describe(r.errors);
  const DeviceProfile& p = *r.profile;
  EXPECT_EQ(p.name, "third-party meter");
  EXPECT_EQ(p.kind, DeviceKind::vfc_meter);
  EXPECT_EQ(p.unit_id, 9);
  ASSERT_EQ(p.signals.size(), 9u);

  const ProfileSignal* start = p.find("gate_start");
  ASSERT_NE(start, nullptr);
  EXPECT_EQ(start->encoding.type, ValueType::boolean);
  EXPECT_EQ(start->access, Access::rw) << "the bench writes it, so rw by default";
  EXPECT_EQ(start->unit_id, 9);

  const ProfileSignal* length = p.find("gate_length_ms");
  ASSERT_NE(length, nullptr);
  EXPECT_EQ(length->unit, "ms") << "unit defaults to the catalogue's";
  EXPECT_EQ(length->encoding.word_order, WordOrder::little) << "device-level default";
  EXPECT_EQ(length->encoding.byte_order, ByteOrder::little) << "device-level default";
  EXPECT_EQ(length->encoding.min, 1);
  EXPECT_EQ(length->encoding.max, 1000);

  const ProfileSignal* status = p.find("gate_status");
  ASSERT_NE(status, nullptr);
  EXPECT_EQ(status->encoding.byte_order, ByteOrder::big) << "signal overrides the device default";
  EXPECT_EQ(status->access, Access::r);
  EXPECT_TRUE(std::isinf(status->encoding.max)) << "no limits given, none imposed";
  EXPECT_TRUE(status->values.empty());

  EXPECT_EQ(p.find("counts_m")->encoding.word_order, WordOrder::big);
  EXPECT_EQ(p.find("counts_g")->unit_id, 10) << "same address, another unit id: no overlap";
  EXPECT_EQ(p.find("gate_s")->access, Access::r) << "read-only holding register needs no limits";
  EXPECT_EQ(p.find("gate_s")->encoding.scale, 0.001);
  EXPECT_EQ(p.find("idcm_A")->encoding.offset, -1);
  EXPECT_EQ(p.find("idcg_A")->encoding.type, ValueType::f32);
  EXPECT_EQ(p.find("speed_rpm"), nullptr);

  // Ordered by table, unit id, address: coil, holding 0, 2, input 0, 1, 2, 4, 5, then unit id 10.
  std::vector<std::string> order;
  for (const ProfileSignal& s : p.signals) order.push_back(s.name);
  EXPECT_EQ(order, (std::vector<std::string>{"gate_start", "gate_length_ms", "gate_s", "gate_status",
                                             "gate_sequence", "counts_m", "idcm_A", "idcg_A", "counts_g"}));
}

TEST(DeviceProfile, ProfileEncodingDrivesTheCodec) {
  // The third-party meter is DCBA: gate_length_ms 1000 = 0x000003E8 goes out as E803 0000.
  const ProfileParseResult r = parse_device_profile(minimal_meter());
  ASSERT_TRUE(r.profile) << describe(r.errors);
  std::uint16_t words[2] = {};
  ASSERT_FALSE(encode_registers(r.profile->find("gate_length_ms")->encoding, 1000, words));
  EXPECT_EQ(words[0], 0xE803);
  EXPECT_EQ(words[1], 0x0000);
  EXPECT_EQ(encode_registers(r.profile->find("gate_length_ms")->encoding, 1001, words), errc::invalid_argument);
}

TEST(DeviceProfile, EnumValuesAreSortedByValue) {
  json doc = minimal_meter();
  doc["signals"]["gate_status"]["values"] = {{"open", 1}, {"done", 2}, {"idle", 0}};
  const ProfileParseResult r = parse_device_profile(doc);
  ASSERT_TRUE(r.profile) << describe(r.errors);
  const auto& v = r.profile->find("gate_status")->values;
  ASSERT_EQ(v.size(), 3u);
  EXPECT_EQ(v[0].value, 0);
  EXPECT_EQ(v[0].label, "idle");
  EXPECT_EQ(v[2].value, 2);
  EXPECT_EQ(v[2].label, "done");
}

TEST(DeviceProfile, AdjacentSignalsDoNotOverlap) {
  json doc = minimal_meter();
  doc["signals"]["idcm_A"]["address"] = 4;  // first free address after counts_m
  EXPECT_TRUE(parse_device_profile(doc).profile);
  doc["signals"]["idcm_A"]["address"] = 3;
  const ProfileParseResult r = parse_device_profile(doc);
  ASSERT_EQ(r.errors.size(), 1u) << describe(r.errors);
  EXPECT_EQ(r.errors[0].pointer, "/signals/idcm_A/address");
}

TEST(DeviceProfile, LoadReportsUnreadableAndMalformedFiles) {
  ProfileParseResult r = load_device_profile("/nonexistent/profile.json");
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_EQ(r.errors[0].pointer, "");
  EXPECT_NE(r.errors[0].reason.find("cannot open"), std::string::npos);

  const std::string bad = testing::TempDir() + "synbench_bad_profile.json";
  std::ofstream(bad) << "{ \"name\": ";
  r = load_device_profile(bad);
  ASSERT_EQ(r.errors.size(), 1u);
  EXPECT_NE(r.errors[0].reason.find("not valid JSON"), std::string::npos) << r.errors[0].reason;
}

TEST(DeviceProfile, JsonPointerTokenEscapes) {
  EXPECT_EQ(json_pointer_token("speed_rpm"), "speed_rpm");
  EXPECT_EQ(json_pointer_token("a/b~c"), "a~1b~0c");
}

}  // namespace
}  // namespace synbench::drivers
