// Tests of the probe on an in-memory bus: hand-computed words decoded as the bench decodes them,
// one read per readable signal and never a write, and a signal that fails (on the link, or in
// decoding) reported with its words while the probe goes on with the next.
#include <gtest/gtest.h>

#include <algorithm>

#include "drivers/error.hpp"
#include "drivers/profile_devices/probe.hpp"
#include "tests/drivers/profile/vendor_profiles.hpp"
#include "tests/drivers/profile_devices/fake_bus.hpp"

namespace synbench::drivers {
namespace {

using testing::FakeBus;

DeviceProfile load_default(DeviceKind kind) {
  ProfileParseResult r = load_device_profile(default_profile_path(kind));
  if (!r.profile) throw std::runtime_error("default profile does not parse");
  return *r.profile;
}

const ProbeRow& row(const std::vector<ProbeRow>& rows, const std::string& signal) {
  const auto it = std::find_if(rows.begin(), rows.end(), [&](const ProbeRow& r) { return r.signal == signal; });
  if (it == rows.end()) throw std::runtime_error("no row for " + signal);
  return *it;
}

TEST(Probe, ReadsEveryReadableSignalOnceAndNeverWrites) {
  const DeviceProfile p = load_default(DeviceKind::synrm_drive);
  FakeBus bus;
  const auto rows = probe_device(bus, p);
  const auto readable = std::count_if(p.signals.begin(), p.signals.end(), [](const ProfileSignal& s) { return s.readable(); });
  ASSERT_EQ(rows.size(), static_cast<std::size_t>(readable));
  ASSERT_EQ(bus.log.size(), rows.size());
  for (const auto& r : bus.log) EXPECT_EQ(r.op, "read");
  // Write-only signals (heartbeat, fault_reset, window_start) cannot be read back.
  for (const char* w : {"heartbeat", "fault_reset", "window_start"})
    EXPECT_THROW(row(rows, w), std::runtime_error) << w;
  for (const ProbeRow& r : rows) EXPECT_EQ(r.profile, p.name);
}

TEST(Probe, RawWordsBesideTheDecodedValue) {
  const DeviceProfile p = load_default(DeviceKind::synrm_drive);
  FakeBus bus;
  // speed_rpm: f32 at input 16-17, big word order: 1234.5 is 0x449A5000.
  bus.at(1, RegisterKind::input, 16) = 0x449A;
  bus.at(1, RegisterKind::input, 17) = 0x5000;
  // udc_V: u16 scale 0.1 at input 30: 4250 = 0x109A is 425.0 V.
  bus.at(1, RegisterKind::input, 30) = 0x109A;
  bus.at(1, RegisterKind::input, 0) = 3;  // state faulted
  bus.at(1, RegisterKind::input, 1) = 6;  // fault watchdog
  bus.at(1, RegisterKind::coil, 0) = 1;   // enable
  const auto rows = probe_device(bus, p);

  const ProbeRow& speed = row(rows, "speed_rpm");
  EXPECT_EQ(speed.table, RegisterKind::input);
  EXPECT_EQ(speed.address, 16);
  EXPECT_EQ(speed.count, 2);
  EXPECT_EQ(speed.unit_id, 1);
  EXPECT_EQ(speed.raw, (std::vector<std::uint16_t>{0x449A, 0x5000}));
  ASSERT_TRUE(speed.value);
  EXPECT_DOUBLE_EQ(*speed.value, 1234.5);
  EXPECT_EQ(speed.unit, "rpm");
  EXPECT_TRUE(speed.error.empty());

  const ProbeRow& udc = row(rows, "udc_V");
  EXPECT_EQ(udc.raw, std::vector<std::uint16_t>{0x109A});
  EXPECT_NEAR(*udc.value, 425.0, 1e-9);
  EXPECT_EQ(udc.unit, "V");

  EXPECT_EQ(row(rows, "state").label, "faulted");
  EXPECT_EQ(row(rows, "fault_code").label, "watchdog");
  EXPECT_EQ(*row(rows, "fault_code").value, 6);
  const ProbeRow& enable = row(rows, "enable");
  EXPECT_EQ(enable.table, RegisterKind::coil);
  EXPECT_EQ(enable.raw, std::vector<std::uint16_t>{1});
  EXPECT_EQ(*enable.value, 1);
  EXPECT_TRUE(row(rows, "speed_rpm").label.empty());
}

TEST(Probe, AFailedSignalIsReportedAndTheProbeGoesOn) {
  const DeviceProfile p = load_default(DeviceKind::synrm_drive);
  FakeBus bus;
  bus.at(1, RegisterKind::input, 30) = 4000;
  bus.at(1, RegisterKind::input, 0) = 9;  // state: no such code
  // The link fails on the request for speed_rpm (input 16), once.
  bus.before = [&](const FakeBus::Request& r) {
    if (r.kind == RegisterKind::input && r.address == 16) bus.fail_next = make_error_code(errc::timeout);
  };
  const auto rows = probe_device(bus, p);

  const ProbeRow& state = row(rows, "state");
  EXPECT_FALSE(state.value);
  EXPECT_EQ(state.raw, std::vector<std::uint16_t>{9});
  EXPECT_NE(state.error.find("9 is outside the profile's limits [0, 3]"), std::string::npos) << state.error;

  const ProbeRow& speed = row(rows, "speed_rpm");
  EXPECT_FALSE(speed.value);
  EXPECT_TRUE(speed.raw.empty());
  EXPECT_FALSE(speed.error.empty());
  // The signals after it were read.
  EXPECT_NEAR(*row(rows, "udc_V").value, 400.0, 1e-9);
  EXPECT_TRUE(row(rows, "window_s").value);
}

TEST(Probe, ACodeWithoutALabelSaysSo) {
  DeviceProfile p = load_default(DeviceKind::load_drive);
  FakeBus bus;
  // A device with its own state codes: 0 is not one of them.
  for (ProfileSignal& s : p.signals)
    if (s.name == "state") {
      s.values = {{1, "running"}, {4, "faulted"}, {5, "disabled"}, {7, "stopping"}};
      s.encoding.max = 7;
    }
  const auto rows = probe_device(bus, p);
  const ProbeRow& state = row(rows, "state");
  EXPECT_FALSE(state.value);
  EXPECT_NE(state.error.find("device code 0 has no label"), std::string::npos) << state.error;
  bus.at(row(rows, "state").unit_id, RegisterKind::input, row(rows, "state").address) = 5;
  EXPECT_EQ(row(probe_device(bus, p), "state").label, "disabled");
}

// A masked signal's error is decoded through its mask, as the bench decodes it: the status word's
// other bits do not leak into the code or the value the message names.
TEST(Probe, AMaskedSignalsErrorNamesItsFieldNotTheWholeWord) {
  synbench::Json doc = synbench::testing::vendor_words(synbench::testing::default_profile_doc(DeviceKind::synrm_drive),
                                                       synbench::testing::pulse_reset());
  doc["signals"]["state"].erase("otherwise");
  doc["signals"]["state"]["values"].erase("stopping");
  // The winding temperature in the status word's high byte, in degC, 0..100.
  doc["signals"]["temp_C"] = {{"register", "input"}, {"address", 40}, {"type", "u16"}, {"mask", 0xFF00},
                              {"unit", "C"}, {"min", 0}, {"max", 100}};
  const DeviceProfile p = synbench::testing::parse_or_throw(doc);
  FakeBus bus;
  bus.at(p.unit_id, RegisterKind::input, 40) = 0xC8F6;  // state bits 0x000B: 2; temperature byte: 200
  const auto rows = probe_device(bus, p);

  const ProbeRow& state = row(rows, "state");
  EXPECT_FALSE(state.value);
  EXPECT_EQ(state.raw, std::vector<std::uint16_t>{0xC8F6});
  EXPECT_NE(state.error.find("signal state (input 40 mask 11, unit id " + std::to_string(p.unit_id) + ")"),
            std::string::npos) << state.error;
  EXPECT_NE(state.error.find("raw 0xC8F6: device code 2 has no label"), std::string::npos) << state.error;

  const ProbeRow& temp = row(rows, "temp_C");
  EXPECT_FALSE(temp.value);
  EXPECT_NE(temp.error.find("signal temp_C (input 40 mask 65280"), std::string::npos) << temp.error;
  EXPECT_NE(temp.error.find("raw 0xC8F6: 200 is outside the profile's limits [0, 100]"), std::string::npos)
      << temp.error;

  // The same word with the fields in range decodes, whatever the other bits hold.
  bus.at(p.unit_id, RegisterKind::input, 40) = 0x32F3;
  const auto ok = probe_device(bus, p);
  EXPECT_EQ(row(ok, "state").label, "running");
  EXPECT_EQ(*row(ok, "temp_C").value, 50);
}

}  // namespace
}  // namespace synbench::drivers
