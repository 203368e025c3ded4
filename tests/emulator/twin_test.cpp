// The twin as a device: windows cover exactly the gate, runs are reproducible, faults latch.
#include "emulator/twin.hpp"

#include <gtest/gtest.h>

#include "drivers/error.hpp"
#include "point_runner.hpp"

namespace synbench {
namespace {

using testing::measure;

TEST(Twin, WindowCoversExactlyTheGateOnEveryInstrument) {
  const emulator::TwinConfig cfg;
  const auto r = measure(cfg, 500, 1.5, 54, drivers::Pwm::capwm, 0.25);
  EXPECT_EQ(r.samples, 2500u);
  EXPECT_DOUBLE_EQ(r.window_s, 0.25);
}

TEST(Twin, SameSeedSameRecordOtherSeedOtherNoise) {
  emulator::TwinConfig cfg;
  const auto a = measure(cfg, 500, 1.5, 54);
  const auto b = measure(cfg, 500, 1.5, 54);
  EXPECT_EQ(a.pdcm_W, b.pdcm_W);
  EXPECT_EQ(a.im_A, b.im_A);
  cfg.sim.seed_int = 7;
  const auto c = measure(cfg, 500, 1.5, 54);
  EXPECT_NE(a.im_A, c.im_A);
  // Repeatability of P_dcM far below the watts that separate configurations (experiment.md 4).
  EXPECT_NEAR(a.pdcm_W, c.pdcm_W, 0.2);
}

TEST(Twin, ExternalTripLatchesUntilAnExplicitReset) {
  const emulator::TwinConfig cfg;
  emulator::TwinBench bench(cfg);
  auto d = bench.devices();
  ASSERT_FALSE(d.synrm->set_angle_deg(50));
  ASSERT_FALSE(d.synrm->set_speed_rpm(900));
  ASSERT_FALSE(d.synrm->enable(true));
  bench.clock().wait_until(1.0);
  drivers::SynrmTelemetry t;
  ASSERT_FALSE(d.synrm->read(t));
  EXPECT_EQ(t.state, drivers::DriveState::running);

  // An external trip (E-stop) gates the drive off and latches.
  bench.twin().synrm_drive().trip(drivers::Fault::estop);
  bench.clock().wait_until(1.5);
  ASSERT_FALSE(d.synrm->read(t));
  EXPECT_EQ(t.state, drivers::DriveState::faulted);
  EXPECT_EQ(t.fault, drivers::Fault::estop);
  EXPECT_EQ(d.synrm->enable(true), make_error_code(errc::device_fault));
  bench.clock().wait_until(3.0);
  EXPECT_LT(bench.twin().snapshot().speed_rpm, 900.0) << "no torque while faulted";
  EXPECT_NEAR(bench.twin().snapshot().iq_A, 0.0, 0.01);
  ASSERT_FALSE(d.synrm->reset_fault());
  ASSERT_FALSE(d.synrm->read(t));
  EXPECT_EQ(t.state, drivers::DriveState::disabled) << "a reset does not restart";
  EXPECT_FALSE(d.synrm->enable(true));
}

TEST(Twin, OvercurrentTripFromThePlant) {
  emulator::TwinConfig cfg;
  cfg.firmware.overcurrent_trip_A = 1.3;
  cfg.firmware.current_limit_A = 1.25;
  const auto r = measure(cfg, 900, 3.5, 56);
  ASSERT_TRUE(r.fault);
  EXPECT_EQ(*r.fault, "overcurrent");
}

TEST(Twin, WarmerWindingLosesMoreInCopper) {
  emulator::TwinConfig cfg;
  const auto cold = measure(cfg, 700, 2.5, 56);
  cfg.thermal.initial_C = 70.0;
  const auto hot = measure(cfg, 700, 2.5, 56);
  ASSERT_TRUE(cold.truth && hot.truth);
  // Rs(T) = Rs (1 + 0.00393 (T - 50)): 7.9 % more copper loss at 70 degC, same current.
  EXPECT_NEAR(hot.truth->pcu_W / cold.truth->pcu_W, 1.0786, 0.01);
  EXPECT_GT(hot.pdcm_W, cold.pdcm_W + 0.05 * cold.truth->pcu_W);
}

}  // namespace
}  // namespace synbench

namespace synbench {
namespace {

TEST(Twin, OwnOrderedStopRampsDownThenLatches) {
  emulator::TwinBench bench{emulator::TwinConfig{}};
  auto& t = bench.twin();
  auto d = bench.devices();
  ASSERT_FALSE(d.synrm->set_angle_deg(56));
  ASSERT_FALSE(d.synrm->set_speed_rpm(900));
  ASSERT_FALSE(d.synrm->enable(true));
  ASSERT_FALSE(d.load->enable(true));
  bench.clock().wait_until(1.5);
  ASSERT_FALSE(d.load->set_torque_Nm(2.0));
  bench.clock().wait_until(3.0);
  // What a watchdog does: both drives stop on their own.
  t.load_drive().stop_and_latch(drivers::Fault::watchdog);
  t.synrm_drive().stop_and_latch(drivers::Fault::watchdog);
  EXPECT_EQ(t.synrm_drive().state(), drivers::DriveState::stopping);
  EXPECT_EQ(d.synrm->set_speed_rpm(900), make_error_code(errc::device_fault)) << "no commands while stopping";
  bench.clock().wait_until(3.2);
  EXPECT_GT(t.snapshot().speed_rpm, 500) << "a ramp, not a coast";
  EXPECT_EQ(t.synrm_drive().state(), drivers::DriveState::stopping);
  bench.clock().wait_until(5.0);
  EXPECT_EQ(t.synrm_drive().state(), drivers::DriveState::faulted);
  EXPECT_EQ(t.synrm_drive().fault(), drivers::Fault::watchdog);
  EXPECT_LT(std::fabs(t.snapshot().speed_rpm), 25.0);
  drivers::LoadTelemetry lt;
  ASSERT_FALSE(d.load->read(lt));
  EXPECT_EQ(lt.state, drivers::DriveState::faulted);
  EXPECT_EQ(lt.fault, drivers::Fault::watchdog);
  EXPECT_NEAR(t.snapshot().load_torque_Nm, 0.0, 1e-9);
  EXPECT_EQ(d.synrm->enable(true), make_error_code(errc::device_fault));
  ASSERT_FALSE(d.synrm->reset_fault());
  ASSERT_FALSE(d.load->reset_fault());
  EXPECT_FALSE(d.synrm->enable(true));
}

}  // namespace
}  // namespace synbench

namespace synbench {
namespace {

// An E-stop from the master in the middle of the drive's own ordered stop (a watchdog's) turns
// the gates off at once instead of being refused: the current is gone in the next period and
// the watchdog's fault latches.
TEST(Twin, DisableDuringTheDrivesOwnStopIsObeyed) {
  emulator::TwinBench bench{emulator::TwinConfig{}};
  auto& t = bench.twin();
  auto d = bench.devices();
  ASSERT_FALSE(d.synrm->set_angle_deg(56));
  ASSERT_FALSE(d.synrm->set_speed_rpm(900));
  ASSERT_FALSE(d.synrm->enable(true));
  ASSERT_FALSE(d.load->enable(true));
  bench.clock().wait_until(1.5);
  ASSERT_FALSE(d.load->set_torque_Nm(2.0));
  bench.clock().wait_until(3.0);
  t.load_drive().stop_and_latch(drivers::Fault::watchdog);
  t.synrm_drive().stop_and_latch(drivers::Fault::watchdog);
  bench.clock().wait_until(3.05);
  ASSERT_EQ(t.synrm_drive().state(), drivers::DriveState::stopping);
  EXPECT_FALSE(d.synrm->enable(false));
  EXPECT_FALSE(d.load->enable(false));
  bench.clock().wait_until(3.06);
  EXPECT_EQ(t.synrm_drive().state(), drivers::DriveState::faulted);
  EXPECT_EQ(t.synrm_drive().fault(), drivers::Fault::watchdog);
  drivers::LoadTelemetry lt;
  ASSERT_FALSE(d.load->read(lt));
  EXPECT_EQ(lt.state, drivers::DriveState::faulted);
  drivers::SynrmTelemetry st;
  ASSERT_FALSE(d.synrm->read(st));
  EXPECT_GT(st.speed_rpm, 500) << "coasting, not ramped down: the gates went off";
  bench.clock().wait_until(3.2);
  EXPECT_LT(std::fabs(t.snapshot().load_torque_Nm), 1e-9);
}

}  // namespace
}  // namespace synbench
