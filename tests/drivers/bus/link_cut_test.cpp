// The link cut for 2 s in the middle of a run, over Modbus TCP in real time: the twin's drive
// stops on its own watchdog and stays faulted until the bench resets it; the bench's bus
// reconnects (bounded backoff) within 5 s of the link's return.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>

#include "drivers/error.hpp"
#include "drivers/profile_devices/profile_bench.hpp"
#include "drivers/real_time_clock.hpp"
#include "tests/drivers/bus/modbus_link_fixture.hpp"

namespace synbench::drivers {
namespace {

using testing::Emulator;

TEST(LinkCut, WatchdogStopsTheDriveAndTheBusReconnects) {
  Emulator emu;
  ModbusTcpBus bus({"127.0.0.1", emu.start_tcp()}, testing::link_options(0.2));
  RealTimeClock clock;
  ProfileBench bench(bus, emu.profiles[0], bus, emu.profiles[1], bus, emu.profiles[2], clock);
  auto wait = [&](double s) { bench.clock().wait_until(clock.now_s() + s); };

  ASSERT_FALSE(bench.load().set_torque_Nm(0.3));
  ASSERT_FALSE(bench.load().enable(true));
  ASSERT_FALSE(bench.synrm().set_angle_deg(52));
  ASSERT_FALSE(bench.synrm().set_speed_rpm(300));
  ASSERT_FALSE(bench.synrm().enable(true));
  wait(1.0);
  SynrmTelemetry t;
  ASSERT_FALSE(bench.synrm().read(t)) << bus.last_error();
  ASSERT_EQ(t.state, DriveState::running);
  ASSERT_GT(t.speed_rpm, 200);

  // Cut: the bench keeps trying (heartbeats, telemetry) every 50 ms.
  const double cut_s = 2.0;
  emu.faults.cut_link(cut_s);
  const double cut_at = clock.now_s();
  double back_at = -1;
  while (clock.now_s() - cut_at < cut_s + 10) {
    wait(0.05);
    if (!bench.synrm().read(t)) {
      back_at = clock.now_s();
      break;
    }
  }
  ASSERT_GT(back_at, 0) << "no reconnection: " << bus.last_error();
  const double reconnect_s = back_at - (cut_at + cut_s);
  std::printf("link back after the 2 s cut: first good reply %.3f s later\n", reconnect_s);
  EXPECT_LT(reconnect_s, 5.0);
  EXPECT_GE(back_at - cut_at, cut_s - 0.05);  // nothing got through the cut

  // The drive stopped on its own, in order, and latched the watchdog fault.
  EXPECT_EQ(t.state, DriveState::faulted);
  EXPECT_EQ(t.fault, Fault::watchdog);
  EXPECT_LT(std::abs(t.speed_rpm), 30);
  EXPECT_EQ(emu.service.locked([](auto&, emulator::TwinSignals& s, auto&) { return s.watchdog_trips(); }), 1u);

  // Heartbeats flow again, the fault stays until the bench resets it.
  wait(1.0);
  ASSERT_FALSE(bench.synrm().read(t));
  EXPECT_EQ(t.state, DriveState::faulted);
  ASSERT_FALSE(bench.synrm().reset_fault());
  ASSERT_FALSE(bench.load().reset_fault());
  ASSERT_FALSE(bench.synrm().read(t));
  EXPECT_EQ(t.state, DriveState::disabled);
  EXPECT_EQ(t.fault, Fault::none);

  const BusStats s = bus.stats();
  std::printf("bus: %llu link errors, %llu timeouts, %llu connect failures, %llu refused during backoff, %llu connects\n",
              static_cast<unsigned long long>(s.link_errors), static_cast<unsigned long long>(s.timeouts),
              static_cast<unsigned long long>(s.connect_failures),
              static_cast<unsigned long long>(s.refused_while_down), static_cast<unsigned long long>(s.connects));
  EXPECT_GE(s.link_errors + s.timeouts, 1u);
  EXPECT_GE(s.connect_failures, 1u);
  EXPECT_GE(s.refused_while_down, 1u);
  EXPECT_EQ(s.connects, 2u);
}

}  // namespace
}  // namespace synbench::drivers
