// Tests of the bench cross-checks: devices whose registers collide on one link, the same
// collision only when served on one endpoint, and one serial port named by two links.
#include <gtest/gtest.h>
#include "drivers/json.hpp"

#include "drivers/bench_check.hpp"

namespace synbench::drivers {
namespace {

using json = synbench::Json;

json config(const std::string& meter_link, int load_unit) {
  return json{{"links",
               {{"a", {{"transport", "tcp"}, {"host", "127.0.0.1"}, {"port", 1502}}},
                {"b", {{"transport", "tcp"}, {"host", "127.0.0.1"}, {"port", 1503}}}}},
              {"devices",
               {{"synrm_drive", {{"profile", "default"}, {"link", "a"}}},
                {"load_drive", {{"profile", "default"}, {"link", "a"}, {"unit_id", load_unit}}},
                {"vfc_meter", {{"profile", "default"}, {"link", meter_link}, {"unit_id", 1}}}}}};
}

std::vector<ProfileError> check(const json& doc, bool one_endpoint) {
  BenchConfigResult r = parse_bench_config(doc, ".");
  EXPECT_TRUE(r.config);
  std::vector<ProfileError> errors;
  auto profiles = load_bench_profiles(*r.config, errors);
  EXPECT_TRUE(profiles);
  return check_bench(*r.config, *profiles, one_endpoint);
}

TEST(BenchCheck, DistinctUnitsOrLinksPass) {
  // The meter at unit 1 like the drive, but on its own link.
  EXPECT_TRUE(check(config("b", 2), false).empty());
}

TEST(BenchCheck, CollidingRegistersOnOneLinkNameBothSignals) {
  const auto errors = check(config("b", 1), false);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].pointer, "/devices/load_drive/profile");
  // Coil 0 is `enable` on both drives.
  EXPECT_NE(errors[0].reason.find("signal 'enable' (coil 0 at unit id 1) overlaps synrm_drive's signal 'enable'"),
            std::string::npos)
      << errors[0].reason;
  EXPECT_NE(errors[0].reason.find("on link 'a'"), std::string::npos);
}

TEST(BenchCheck, OneEndpointSeesEveryDevice) {
  const auto errors = check(config("b", 2), true);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].pointer, "/devices/vfc_meter/profile");
  EXPECT_NE(errors[0].reason.find("on the one endpoint"), std::string::npos) << errors[0].reason;
}

TEST(BenchCheck, OneSerialPortIsOneLink) {
  json doc = config("b", 2);
  doc["links"]["a"] = {{"transport", "rtu"}, {"device", "/dev/ttyUSB0"}};
  doc["links"]["b"] = {{"transport", "rtu"}, {"device", "/dev/ttyUSB0"}};
  const auto errors = check(doc, false);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].pointer, "/links/b/device");
  EXPECT_NE(errors[0].reason.find("is also link 'a'"), std::string::npos);
}

}  // namespace
}  // namespace synbench::drivers
