// Which telemetry values the frozen-telemetry check can watch: a profile drive reports the steps
// of its registers (types, scales, masks) as its TelemetryResolution, the steps are set against
// a running drive's noise, and `synbench bench check` names what is left unwatched and why.
#include "drivers/frozen_watch.hpp"

#include <gtest/gtest.h>
#include "drivers/json.hpp"

#include <fstream>

#include "drivers/bench_check.hpp"
#include "drivers/profile_devices/profile_drives.hpp"
#include "tests/drivers/profile_devices/fake_bus.hpp"

namespace synbench::drivers {
namespace {

using json = synbench::Json;

json host_window_synrm() {
  std::ifstream in(std::filesystem::path(SYNBENCH_TEST_PROFILE_DIR) / "synrm_host_window.json");
  return json::parse(in);
}

DeviceProfile parse(const json& doc) {
  ProfileParseResult r = parse_device_profile(doc);
  if (!r.profile) throw std::runtime_error(r.errors.front().pointer + ": " + r.errors.front().reason);
  return *r.profile;
}

TEST(FrozenWatch, AProfileDrivesResolutionIsItsRegistersSteps) {
  json doc = host_window_synrm();
  auto& s = doc["signals"];
  // A commercial drive's currents: i16 in 0.01 A, i32 in uA (word-swapped), and a magnitude in a
  // masked field of a u16 in 0.05 A steps (the field is read shifted: its step is the scale).
  s["id_A"] = {{"register", "input"}, {"address", 20}, {"type", "i16"}, {"scale", 0.01}, {"unit", "A"}};
  s["iq_A"] = {{"register", "input"}, {"address", 22}, {"type", "i32"}, {"word_order", "little"},
               {"scale", -1e-6}, {"unit", "A"}};
  s["im_A"] = {{"register", "input"}, {"address", 18}, {"type", "u16"}, {"mask", 0x0FF0}, {"scale", 0.05},
               {"unit", "A"}};
  testing::FakeBus bus;
  const ProfileSynrmDrive drive(bus, parse(doc));
  const TelemetryResolution r = drive.resolution();
  EXPECT_DOUBLE_EQ(r.id_A, 0.01);
  EXPECT_DOUBLE_EQ(r.iq_A, 1e-6);  // |scale|: a negative scale steps as much
  EXPECT_DOUBLE_EQ(r.im_A, 0.05);
  EXPECT_EQ(r.speed_rpm, 0.0);  // f32: continuous
  EXPECT_EQ(r.ud_V, 0.0);
  // The interface's default, as the in-process twin reports it: all continuous.
  const TelemetryResolution twin;
  EXPECT_TRUE(frozen_blind_spots(twin).empty());
  const auto blind = frozen_blind_spots(r);
  ASSERT_EQ(blind.size(), 2u);
  EXPECT_EQ(blind[0].signal, "im_A");
  EXPECT_EQ(blind[1].signal, "id_A");  // iq_A in uA stays watched
}

TEST(FrozenWatch, BenchCheckNamesTheSignalsItCannotWatchAndWhy) {
  json doc = host_window_synrm();
  doc["signals"]["id_A"] = {{"register", "input"}, {"address", 20}, {"type", "i16"}, {"scale", 0.01}, {"unit", "A"}};
  BenchProfiles p{parse(doc), {}, {}};
  const auto blind = frozen_check_blind_spots(p);
  ASSERT_EQ(blind.size(), 1u);
  const std::string text = blind[0].describe();
  EXPECT_EQ(text.rfind("id_A: 0.01 A steps, coarser than its noise (~", 0), 0u) << text;
  EXPECT_NE(text.find(" mA): a frozen value cannot be told from a steady one"), std::string::npos) << text;
  // At 0.01 mA steps, finer than the noise: watched.
  doc["signals"]["id_A"]["scale"] = 1e-5;
  BenchProfiles fine{parse(doc), {}, {}};
  EXPECT_TRUE(frozen_check_blind_spots(fine).empty());
}

}  // namespace
}  // namespace synbench::drivers
