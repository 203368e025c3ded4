// Array signals (a profile's "count") through SignalIo: each value decoded with the signal's
// encoding from consecutive registers, read in the same request as its neighbours, a value
// outside the limits refused naming its index; and the Modbus requests a window read of the
// default profiles costs with the batch arrays (in their contiguous blocks).
#include <gtest/gtest.h>

#include <string_view>
#include <vector>

#include "drivers/device_signals.hpp"
#include "drivers/error.hpp"
#include "drivers/profile_devices/signal_io.hpp"
#include "tests/drivers/default_profiles.hpp"
#include "tests/drivers/profile_devices/fake_bus.hpp"

namespace synbench::drivers {
namespace {

using testing::FakeBus;

// A vendor's load drive: batch torques as i16 of 0.01 Nm, little-endian bytes, next to the mean.
DeviceProfile vendor_load() {
  synbench::Json doc = synbench::testing::json_doc(default_profile_path(DeviceKind::load_drive));
  doc["signals"]["window_torque_Nm"] = synbench::Json::parse(
      R"({"register": "input", "address": 104, "type": "i16", "scale": 0.01, "byte_order": "little",
          "unit": "Nm", "min": -100, "max": 100})");
  doc["signals"]["window_batch_torque_Nm"] = synbench::Json::parse(
      R"({"register": "input", "address": 105, "count": 4, "type": "i16", "scale": 0.01, "byte_order": "little",
          "unit": "Nm", "min": -100, "max": 100})");
  const ProfileParseResult r = parse_device_profile(doc);
  if (!r.profile) throw std::runtime_error(r.errors.front().pointer + ": " + r.errors.front().reason);
  return *r.profile;
}

TEST(ArraySignals, EachValueDecodesFromItsOwnRegistersInOneRequestWithItsNeighbours) {
  const DeviceProfile p = vendor_load();
  const ProfileSignal& arr = *p.find("window_batch_torque_Nm");
  EXPECT_EQ(arr.count, 4);
  EXPECT_EQ(arr.last_address(), 108);
  FakeBus bus;
  const std::vector<double> sent = {1.25, -0.5, 2.0, 1.75};
  const auto swapped = [](int raw) {
    const auto w = static_cast<std::uint16_t>(raw);
    return static_cast<std::uint16_t>((w >> 8) | (w << 8));
  };
  bus.at(arr.unit_id, RegisterKind::input, 104) = swapped(138);
  for (std::size_t k = 0; k < sent.size(); ++k)
    bus.at(arr.unit_id, RegisterKind::input, static_cast<std::uint16_t>(105 + k)) =
        swapped(static_cast<int>(std::lround(sent[k] * 100)));
  SignalIo io(bus, p);
  const ReadPlan plan(p, {"window_torque_Nm", "window_batch_torque_Nm"});
  EXPECT_EQ(plan.requests(), 1u);
  std::vector<double> v(plan.size());
  ASSERT_FALSE(io.read(plan, v));
  ASSERT_EQ(bus.log.size(), 1u);
  EXPECT_EQ(bus.log[0].address, 104);
  EXPECT_EQ(bus.log[0].count, 5u);
  EXPECT_NEAR(v[0], 1.38, 1e-9);
  std::vector<double> batches;
  ASSERT_FALSE(io.read_array(plan, "window_batch_torque_Nm", batches));
  ASSERT_EQ(batches.size(), sent.size());
  for (std::size_t k = 0; k < sent.size(); ++k) EXPECT_NEAR(batches[k], sent[k], 1e-9) << k;
  // Not in the plan: not supported.
  EXPECT_EQ(io.read_array(plan, "window_torque_Nm_x", batches), errc::not_supported);

  // A value past the limits is a protocol error naming the signal and the value's index.
  bus.at(arr.unit_id, RegisterKind::input, 107) = swapped(20000);  // 200 Nm
  ASSERT_FALSE(io.read(plan, v));
  EXPECT_EQ(io.read_array(plan, "window_batch_torque_Nm", batches), errc::protocol);
  EXPECT_NE(io.last_error().find("window_batch_torque_Nm (input 105..108"), std::string::npos) << io.last_error();
  EXPECT_NE(io.last_error().find("value 2 of 4"), std::string::npos) << io.last_error();
}

template <class S, std::size_t N>
std::vector<std::string_view> names(std::vector<std::string_view> lead, const SignalField<S> (&table)[N],
                                    bool estimates = false) {
  for (const auto& f : table)
    if ((f.estimate_bit != 0) == estimates) lead.push_back(f.signal);
  return lead;
}

template <class S, std::size_t N>
std::vector<std::string_view> with(std::vector<std::string_view> v, const ArrayField<S> (&arrays)[N]) {
  for (const auto& f : arrays) v.push_back(f.signal);
  return v;
}

// The requests of each window read plan of the default profiles, without and with the batch
// arrays (the drivers add one read of the window's status and sequence, and the meter one of
// its calibration): the SynRM drive's batches are one more block; the load drive's and the
// meter's continue their window blocks.
TEST(ArraySignals, WindowReadsOfTheDefaultProfilesCostOneMoreRequestAtMost) {
  const auto profiles = synbench::testing::default_profiles();
  const auto synrm = names({"window_status", "window_sequence"}, kSynrmWindowSignals);
  const auto load = names({"window_status", "window_sequence"}, kLoadWindowSignals);
  const auto gate = names({"gate_status", "gate_sequence"}, kMeterGateSignals);
  EXPECT_EQ(ReadPlan(profiles[0], synrm).requests(), 3u);
  EXPECT_EQ(ReadPlan(profiles[0], with(synrm, kSynrmWindowArrays)).requests(), 4u);
  EXPECT_EQ(ReadPlan(profiles[1], load).requests(), 1u);
  EXPECT_EQ(ReadPlan(profiles[1], with(load, kLoadWindowArrays)).requests(), 1u);
  EXPECT_EQ(ReadPlan(profiles[2], gate).requests(), 1u);
  EXPECT_EQ(ReadPlan(profiles[2], with(gate, kMeterGateArrays)).requests(), 1u);
  // Every batch array of the default profiles holds the twin's default 10 batches.
  for (const DeviceProfile& p : profiles)
    for (const ProfileSignal& s : p.signals)
      if (find_signal_spec(p.kind, s.name)->array) {
        EXPECT_EQ(s.count, 10) << s.name;
      }
}

}  // namespace
}  // namespace synbench::drivers
