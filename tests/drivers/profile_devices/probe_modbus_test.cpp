// The probe over real Modbus TCP against the twin's server: the twin at rest read back through
// the default profiles (state disabled, the DC bus at its source voltage, the words on the wire
// matching the values), and a signal at an address the device does not map reported with the
// device's exception while the others are read.
#include <gtest/gtest.h>

#include <algorithm>

#include "drivers/profile/register_codec.hpp"
#include "drivers/profile_devices/probe.hpp"
#include "tests/drivers/bus/modbus_link_fixture.hpp"

namespace synbench::drivers {
namespace {

using testing::Emulator;
using testing::link_options;

const ProbeRow& row(const std::vector<ProbeRow>& rows, const std::string& signal) {
  const auto it = std::find_if(rows.begin(), rows.end(), [&](const ProbeRow& r) { return r.signal == signal; });
  if (it == rows.end()) throw std::runtime_error("no row for " + signal);
  return *it;
}

TEST(ProbeOverTcp, TheTwinAtRest) {
  Emulator emu;
  ModbusTcpBus bus({"127.0.0.1", emu.start_tcp()}, link_options(0.5));
  for (const DeviceProfile& p : emu.profiles) {
    const auto rows = probe_device(bus, p);
    ASSERT_FALSE(rows.empty());
    for (const ProbeRow& r : rows) {
      EXPECT_TRUE(r.error.empty()) << r.signal << ": " << r.error;
      EXPECT_EQ(r.raw.size(), r.count) << r.signal;
    }
    if (p.kind == DeviceKind::vfc_meter) continue;
    EXPECT_EQ(row(rows, "state").label, "disabled");
    EXPECT_EQ(row(rows, "fault_code").label, "none");
  }
  const auto synrm = probe_device(bus, emu.profiles[0]);
  const ProbeRow& udc = row(synrm, "udc_V");
  // The bus at rest sits at the source voltage (425 V), in 0.1 V steps on the wire.
  EXPECT_NEAR(*udc.value, emulator::TwinConfig{}.dc_bus.source_V, 5.0);
  EXPECT_NEAR(udc.raw[0] * 0.1, *udc.value, 1e-9);
  // A float's two words, big word order, are its IEEE-754 bits.
  const ProbeRow& speed = row(synrm, "speed_rpm");
  double decoded = 0;
  RegisterEncoding f32;
  f32.type = ValueType::f32;
  ASSERT_FALSE(decode_registers(f32, speed.raw, decoded));
  EXPECT_DOUBLE_EQ(decoded, *speed.value);
  EXPECT_NEAR(*speed.value, 0.0, 1.0);
  // The probe never wrote: the heartbeat the twin holds is still its initial zero.
  std::uint16_t heartbeat = 1;
  ASSERT_FALSE(bus.read_registers(1, RegisterKind::holding, 0, std::span(&heartbeat, 1)));
  EXPECT_EQ(heartbeat, 0);
}

TEST(ProbeOverTcp, AnUnmappedAddressIsTheDevicesException) {
  Emulator emu;
  ModbusTcpBus bus({"127.0.0.1", emu.start_tcp()}, link_options(0.5));
  DeviceProfile p = emu.profiles[0];
  for (ProfileSignal& s : p.signals)
    if (s.name == "pac_W") s.address = 900;  // the twin maps nothing there
  const auto rows = probe_device(bus, p);
  const ProbeRow& pac = row(rows, "pac_W");
  EXPECT_FALSE(pac.value);
  EXPECT_NE(pac.error.find("Illegal data address"), std::string::npos) << pac.error;
  EXPECT_TRUE(row(rows, "udc_V").value);
  EXPECT_TRUE(row(rows, "window_s").value);
}

}  // namespace
}  // namespace synbench::drivers
