// Bits of one control word over real Modbus (TCP on loopback, RTU through a socat pty pair) to
// the twin served through a vendor-style profile: each signal's write is a read-modify-write of
// the shared register, so the others' bits survive it, and the status word's bits give the state.
#include <gtest/gtest.h>

#include <memory>

#include "drivers/bus/modbus_bus.hpp"
#include "drivers/profile_devices/signal_io.hpp"
#include "tests/drivers/bus/modbus_link_fixture.hpp"
#include "tests/drivers/profile/vendor_profiles.hpp"

namespace synbench::drivers {
namespace {

using json = synbench::Json;
namespace t = synbench::testing;

std::vector<DeviceProfile> vendor_bench() {
  return {t::parse_or_throw(t::vendor_synrm(t::pulse_reset(100), t::any_write("speed_setpoint_rpm"))),
          t::parse_or_throw(t::vendor_load(t::level_reset(), t::no_watchdog())),
          t::parse_or_throw(t::default_profile_doc(DeviceKind::vfc_meter))};
}

void control_word_round_trip(RegisterBus& bus, const DeviceProfile& synrm) {
  SignalIo io(bus, synrm);
  const auto word = [&] {
    std::uint16_t w = 0xFFFF;
    EXPECT_FALSE(bus.read_registers(1, RegisterKind::holding, 40, std::span(&w, 1))) << bus.last_error();
    return w;
  };
  ASSERT_FALSE(io.write("pwm_scheme", 1)) << io.last_error();
  EXPECT_EQ(word(), 0x0010);
  ASSERT_FALSE(io.write("speed_setpoint_rpm", 0)) << io.last_error();
  ASSERT_FALSE(io.write("enable", 1)) << io.last_error();
  EXPECT_EQ(word(), 0x0011);
  ASSERT_FALSE(io.write("fault_reset", 1)) << io.last_error();
  EXPECT_EQ(word(), 0x0091);
  ASSERT_FALSE(io.write("fault_reset", 0)) << io.last_error();
  EXPECT_EQ(word(), 0x0011);
  const ReadPlan state(synrm, {"state", "fault_code"});
  double v[2];
  ASSERT_FALSE(io.read(state, v)) << io.last_error();
  EXPECT_EQ(static_cast<DriveState>(static_cast<int>(v[0])), DriveState::running);
  EXPECT_EQ(v[1], 0);
  ASSERT_FALSE(io.write("enable", 0)) << io.last_error();
  EXPECT_EQ(word(), 0x0010);
  ASSERT_FALSE(io.read(state, v)) << io.last_error();
  EXPECT_EQ(static_cast<DriveState>(static_cast<int>(v[0])), DriveState::disabled);
}

TEST(ControlWordOverModbus, Tcp) {
  t::Emulator emu(vendor_bench());
  ModbusTcpBus bus({"127.0.0.1", emu.start_tcp()}, t::link_options(0.5));
  control_word_round_trip(bus, emu.profiles[0]);
}

TEST(ControlWordOverModbus, Rtu) {
  t::SocatPair pty("control_word");
  if (!pty.ok()) GTEST_SKIP() << "socat is not available";
  t::Emulator emu(vendor_bench());
  ASSERT_TRUE(emu.start_rtu(pty.a()));
  RtuPort port;
  port.device = pty.b();
  ModbusRtuBus bus(port, t::link_options(0.2));
  control_word_round_trip(bus, emu.profiles[0]);
}

}  // namespace
}  // namespace synbench::drivers
