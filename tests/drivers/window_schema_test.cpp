// Tests of the window and meter part of a profile: window signals as a group mapped all or
// none, poll_period_ms for a window the bench keeps, the three meter kinds and their signals.
#include "drivers/profile/window_schema.hpp"

#include <gtest/gtest.h>
#include "drivers/json.hpp"
#include "tests/drivers/default_profiles.hpp"

#include <fstream>
#include <string>

namespace synbench::drivers {
namespace {

using json = synbench::Json;

json default_doc(DeviceKind kind) { return testing::json_doc(default_profile_path(kind)); }
json test_doc(const char* file) { return testing::json_doc(std::filesystem::path(SYNBENCH_TEST_PROFILE_DIR) / file); }

std::string describe(const std::vector<ProfileError>& errors) {
  std::string s;
  for (const ProfileError& e : errors) s += "\n  '" + e.pointer + "': " + e.reason;
  return s;
}

// The single error of `doc`, at `path`, its reason containing `reason`.
void expect_error(const json& doc, const std::string& path, const std::string& reason) {
  const ProfileParseResult r = parse_device_profile(doc);
  ASSERT_EQ(r.errors.size(), 1u) << describe(r.errors);
  EXPECT_EQ(r.errors[0].pointer, path);
  EXPECT_NE(r.errors[0].reason.find(reason), std::string::npos) << r.errors[0].reason;
}

TEST(WindowSchema, DefaultProfilesKeepTheirWindowsAndGate) {
  for (const DeviceKind k : kDeviceKinds) {
    const ProfileParseResult r = parse_device_profile(default_doc(k));
    ASSERT_TRUE(r.profile) << describe(r.errors);
    EXPECT_FALSE(host_window(*r.profile));
    EXPECT_EQ(r.profile->meter, MeterKind::gate);
  }
}

TEST(WindowSchema, TestProfilesParse) {
  for (const char* f : {"synrm_host_window.json", "load_host_window.json", "meter_totalizer.json", "meter_power.json"}) {
    const ProfileParseResult r = parse_device_profile(test_doc(f));
    ASSERT_TRUE(r.profile) << f << describe(r.errors);
  }
  const auto synrm = parse_device_profile(test_doc("synrm_host_window.json")).profile;
  EXPECT_TRUE(host_window(*synrm));
  EXPECT_EQ(synrm->poll_period_ms, 50u);
  const auto totalizer = parse_device_profile(test_doc("meter_totalizer.json")).profile;
  EXPECT_EQ(totalizer->meter, MeterKind::totalizer);
  EXPECT_EQ(totalizer->time_base_Hz, 1e6);
  EXPECT_FALSE(host_window(*totalizer));
  EXPECT_TRUE(host_window(*parse_device_profile(test_doc("meter_power.json")).profile));
}

TEST(WindowSchema, AHalfMappedWindowGroupNamesEachMissingSignal) {
  json d = default_doc(DeviceKind::synrm_drive);
  d["signals"].erase("window_sequence");
  expect_error(d, "/signals/window_sequence", "map all of window_start, window_length_ms, window_status");
}

TEST(WindowSchema, AHostWindowNeedsItsPollPeriod) {
  json d = test_doc("synrm_host_window.json");
  d.erase("poll_period_ms");
  expect_error(d, "/poll_period_ms", "required");
  d["poll_period_ms"] = 0;
  expect_error(d, "/poll_period_ms", "1..60000");
}

TEST(WindowSchema, APollPeriodOnADeviceKeptWindowIsRefused) {
  json d = default_doc(DeviceKind::load_drive);
  d["poll_period_ms"] = 50;
  expect_error(d, "/poll_period_ms", "applies only to a profile without window signals");
}

TEST(WindowSchema, AWindowResultWithoutTheDeviceWindowIsRefused) {
  json d = test_doc("load_host_window.json");
  d["signals"]["window_torque_Nm"] = {{"register", "input"}, {"address", 104}, {"type", "f32"}, {"unit", "Nm"}};
  // window_torque_Nm is a member of the load drive's group: the group is now half mapped.
  const ProfileParseResult r = parse_device_profile(d);
  ASSERT_FALSE(r.errors.empty());
  EXPECT_EQ(r.errors[0].pointer, "/signals/window_status") << describe(r.errors);
  json s = test_doc("synrm_host_window.json");
  s["signals"]["window_im_A"] = {{"register", "input"}, {"address", 110}, {"type", "f32"}, {"unit", "A"}};
  expect_error(s, "/signals/window_im_A", "a window result needs the device's window");
}

TEST(WindowSchema, MeterKindsRequireTheirSignalsAndRefuseTheOthers) {
  json t = test_doc("meter_totalizer.json");
  t["signals"].erase("time_base_ticks");
  expect_error(t, "/signals/time_base_ticks", "required for meter totalizer");
  t = test_doc("meter_totalizer.json");
  t.erase("time_base_Hz");
  expect_error(t, "/time_base_Hz", "required");
  t = test_doc("meter_totalizer.json");
  t["signals"]["total_m"]["type"] = "i32";
  t["signals"]["total_m"]["min"] = 0;
  t["signals"]["total_m"]["max"] = 2147483647;
  expect_error(t, "/signals/total_m/type", "u16 or u32");

  json g = default_doc(DeviceKind::vfc_meter);
  g["signals"]["pdcm_W"] = {{"register", "input"}, {"address", 300}, {"type", "f32"}, {"unit", "W"}};
  expect_error(g, "/signals/pdcm_W", "belongs to meter power, not gate");

  json p = test_doc("meter_power.json");
  p["meter"] = "watts";
  expect_error(p, "/meter", "gate, totalizer, power");
  p = test_doc("meter_power.json");
  p.erase("poll_period_ms");
  expect_error(p, "/poll_period_ms", "required");

  json drive = default_doc(DeviceKind::synrm_drive);
  drive["meter"] = "power";
  expect_error(drive, "/meter", "vfc_meter profile only");
}

}  // namespace
}  // namespace synbench::drivers
