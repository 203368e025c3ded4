// The twin served through vendor-style profiles, in-process on virtual time: bits of one control
// word written independently keep each other (read-modify-write against the real register
// server), a pulse reset on an edge-triggered drive resets every time while a level reset does
// so once, and the any_write and none watchdogs as the twin keeps them.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "drivers/error.hpp"
#include "drivers/profile_devices/profile_bench.hpp"
#include "emulator/modbus/twin_register_bus.hpp"
#include "emulator/modbus/twin_service.hpp"
#include "tests/drivers/profile/vendor_profiles.hpp"

namespace synbench::emulator {
namespace {

using drivers::DeviceKind;
using drivers::DriveState;
using drivers::Fault;
using json = synbench::Json;
namespace t = synbench::testing;

drivers::DeviceProfile meter() { return t::parse_or_throw(t::default_profile_doc(DeviceKind::vfc_meter)); }

// The twin serves `served`; the bench reads and writes through `used` (the same map, or one
// that differs in what a test examines).
struct VendorBench {
  std::vector<drivers::DeviceProfile> served;
  TwinService service;
  TwinRegisterBus bus{service};
  TwinServiceClock clock{service};
  drivers::ProfileBench bench;

  VendorBench(const json& synrm_served, const json& load_served, const json& synrm_used, const json& load_used)
      : served{t::parse_or_throw(synrm_served), t::parse_or_throw(load_served), meter()},
        service{TwinConfig{}, served},
        bench{bus, t::parse_or_throw(synrm_used), bus, t::parse_or_throw(load_used), bus, meter(), clock} {}
  VendorBench(const json& synrm, const json& load) : VendorBench(synrm, load, synrm, load) {}

  void spin_up(double rpm) {
    ASSERT_FALSE(bench.load().set_torque_Nm(0.5));
    ASSERT_FALSE(bench.load().enable(true));
    ASSERT_FALSE(bench.synrm().set_angle_deg(52));
    ASSERT_FALSE(bench.synrm().set_speed_rpm(rpm));
    ASSERT_FALSE(bench.synrm().enable(true));
    bench.clock().wait_until(clock.now_s() + 1.5);
  }
  drivers::SynrmTelemetry synrm() {
    drivers::SynrmTelemetry s;
    EXPECT_FALSE(bench.synrm().read(s)) << bench.synrm().error_detail();
    return s;
  }
  drivers::LoadTelemetry load() {
    drivers::LoadTelemetry l;
    EXPECT_FALSE(bench.load().read(l)) << bench.load().error_detail();
    return l;
  }
  std::uint16_t control_word() {
    std::uint16_t w = 0;
    EXPECT_FALSE(bus.read_registers(1, drivers::RegisterKind::holding, 40, std::span(&w, 1)));
    return w;
  }
  // Both drives tripped by their watchdogs (the bench falls silent), then cleared by the bench.
  void trip_and_reset() {
    bench.set_heartbeats(false);
    clock.wait_until(clock.now_s() + 2.5);
    ASSERT_EQ(synrm().state, DriveState::faulted);
    ASSERT_EQ(synrm().fault, Fault::watchdog);
    bench.set_heartbeats(true);
    ASSERT_FALSE(bench.synrm().reset_fault());
    ASSERT_FALSE(bench.load().reset_fault());
    // The bench's clock ends the pulses.
    bench.clock().wait_until(clock.now_s() + 0.3);
  }
};

TEST(VendorWords, BitsOfOneControlWordAreWrittenIndependently) {
  VendorBench v(t::vendor_synrm(t::pulse_reset(100), json()), t::vendor_load(t::level_reset(), json()));
  drivers::SignalIo& io = v.bench.synrm().io();
  EXPECT_EQ(v.control_word(), 0x0000);
  ASSERT_FALSE(io.write("pwm_scheme", 1));  // aspwm: bit 4
  EXPECT_EQ(v.control_word(), 0x0010);
  ASSERT_FALSE(v.bench.synrm().set_speed_rpm(0));
  ASSERT_FALSE(io.write("enable", 1));  // bit 0; the PWM bit stays
  EXPECT_EQ(v.control_word(), 0x0011);
  EXPECT_EQ(v.service.locked([](Twin& tw, auto&, auto&) { return tw.synrm_drive().state(); }), DriveState::running);
  EXPECT_EQ(v.service.locked([](Twin& tw, auto&, auto&) { return tw.synrm_drive().pwm(); }), drivers::Pwm::aspwm);
  ASSERT_FALSE(io.write("fault_reset", 1));  // bit 7, held (a pulse reset reads back)
  EXPECT_EQ(v.control_word(), 0x0091);
  ASSERT_FALSE(io.write("fault_reset", 0));
  EXPECT_EQ(v.control_word(), 0x0011);
  EXPECT_EQ(v.service.locked([](Twin& tw, auto&, auto&) { return tw.synrm_drive().state(); }), DriveState::running);
  // The state comes from the status word's bits: running is 3 under mask 0x000B.
  std::uint16_t status = 0;
  ASSERT_FALSE(v.bus.read_registers(1, drivers::RegisterKind::input, 40, std::span(&status, 1)));
  EXPECT_EQ(status & 0x000B, 3);
  EXPECT_EQ(v.synrm().state, DriveState::running);
  ASSERT_FALSE(io.write("enable", 0));
  EXPECT_EQ(v.control_word(), 0x0010);
  EXPECT_EQ(v.synrm().state, DriveState::disabled);
  // A value that does not fit the bit is refused before anything is written, and said so.
  EXPECT_EQ(io.write("enable", 2), errc::invalid_argument);
  EXPECT_NE(io.last_error().find("signal enable (holding 40 mask 1, unit id 1)"), std::string::npos) << io.last_error();
  EXPECT_EQ(v.control_word(), 0x0010);
}

TEST(VendorWords, APulseResetClearsAnEdgeTriggeredDriveEveryTime) {
  VendorBench v(t::vendor_synrm(t::pulse_reset(100), json()), t::vendor_load(t::pulse_reset(50), json()));
  for (int round = 0; round < 2; ++round) {
    SCOPED_TRACE("round " + std::to_string(round + 1));
    v.spin_up(400);
    ASSERT_EQ(v.synrm().state, DriveState::running);
    v.trip_and_reset();
    EXPECT_EQ(v.synrm().state, DriveState::disabled);
    EXPECT_EQ(v.synrm().fault, Fault::none);
    EXPECT_EQ(v.load().state, DriveState::disabled);
    EXPECT_EQ(v.control_word() & 0x0080, 0) << "the pulse ended";
  }
}

TEST(VendorWords, ALevelResetOnAnEdgeTriggeredDriveResetsOnlyOnce) {
  // The drive resets on a rising edge; the bench's profile says level, so it never clears the bit.
  const json served = t::vendor_synrm(t::pulse_reset(100), json());
  const json used = t::vendor_synrm(t::level_reset(), json());
  const json load = t::vendor_load(t::pulse_reset(50), json());
  VendorBench v(served, load, used, load);
  v.spin_up(400);
  v.trip_and_reset();
  EXPECT_EQ(v.synrm().state, DriveState::disabled);
  EXPECT_NE(v.control_word() & 0x0080, 0) << "a level reset leaves the bit set";
  v.spin_up(400);
  ASSERT_EQ(v.synrm().state, DriveState::running);
  v.trip_and_reset();
  EXPECT_EQ(v.synrm().state, DriveState::faulted) << "no edge, no reset";
}

TEST(VendorWords, AnAnyWriteWatchdogIsFedByTheRefreshAndTripsWithoutIt) {
  const json synrm = t::vendor_synrm(t::pulse_reset(100), t::any_write("speed_setpoint_rpm", 250, 1000));
  VendorBench v(synrm, t::vendor_load(t::level_reset(), t::no_watchdog()));
  v.spin_up(400);
  // Nothing but the refresh reaches the drive for 5 timeouts.
  v.bench.clock().wait_until(v.clock.now_s() + 5.0);
  EXPECT_EQ(v.synrm().state, DriveState::running);
  EXPECT_EQ(v.service.locked([](auto&, TwinSignals& s, auto&) { return s.watchdog_trips(); }), 0u);
  v.bench.set_heartbeats(false);
  v.clock.wait_until(v.clock.now_s() + 0.8);  // within the 1000 ms timeout of the last refresh
  EXPECT_EQ(v.synrm().state, DriveState::running);
  v.clock.wait_until(v.clock.now_s() + 2.5);
  const auto s = v.synrm();
  EXPECT_EQ(s.state, DriveState::faulted);
  EXPECT_EQ(s.fault, Fault::watchdog);
  EXPECT_EQ(v.service.locked([](auto&, TwinSignals& sig, auto&) { return sig.watchdog_trips(); }), 1u);
}

TEST(VendorWords, WithoutAWatchdogTheDrivesRunOnWithoutTheBench) {
  VendorBench v(t::vendor_synrm(t::pulse_reset(100), t::no_watchdog()), t::vendor_load(t::level_reset(), t::no_watchdog()));
  v.spin_up(400);
  v.bench.set_heartbeats(false);
  v.clock.wait_until(v.clock.now_s() + 5.0);
  EXPECT_EQ(v.synrm().state, DriveState::running);
  EXPECT_EQ(v.load().state, DriveState::running);
  EXPECT_EQ(v.service.locked([](auto&, TwinSignals& sig, auto&) { return sig.watchdog_trips(); }), 0u);
}

}  // namespace
}  // namespace synbench::emulator
