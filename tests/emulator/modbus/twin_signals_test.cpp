// Tests of the twin's firmware behind its register map, in-process on virtual time: the
// watchdog's ordered stop and latched fault, the fault reset, the shared window with its
// sequence numbers, and mode changes refused while running.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "drivers/error.hpp"
#include "drivers/profile_devices/profile_bench.hpp"
#include "emulator/modbus/modbus_pdu.hpp"
#include "emulator/modbus/twin_register_bus.hpp"
#include "emulator/modbus/twin_service.hpp"
#include "tests/drivers/default_profiles.hpp"

namespace synbench::emulator {
namespace {

using drivers::DeviceKind;
using drivers::DriveState;
using drivers::Fault;

using testing::default_profiles;

struct TwinFixture : ::testing::Test {
  std::vector<drivers::DeviceProfile> profiles = default_profiles();
  TwinService service{TwinConfig{}, profiles};
  TwinRegisterBus bus{service};
  TwinServiceClock clock{service};
  drivers::ProfileBench bench{bus, profiles[0], bus, profiles[1], bus, profiles[2], clock};

  // Spins the SynRM up to `rpm` with the load enabled, heartbeats running.
  void spin_up(double rpm) {
    ASSERT_FALSE(bench.load().set_torque_Nm(0.5));
    ASSERT_FALSE(bench.load().enable(true));
    ASSERT_FALSE(bench.synrm().set_angle_deg(52));
    ASSERT_FALSE(bench.synrm().set_speed_rpm(rpm));
    ASSERT_FALSE(bench.synrm().enable(true));
    bench.clock().wait_until(clock.now_s() + 1.5);
  }
  drivers::SynrmTelemetry synrm() {
    drivers::SynrmTelemetry t;
    EXPECT_FALSE(bench.synrm().read(t));
    return t;
  }
};

TEST_F(TwinFixture, TelemetryReachesTheDriverThroughTheRegisterMap) {
  spin_up(500);
  const auto t = synrm();
  EXPECT_EQ(t.state, DriveState::running);
  EXPECT_NEAR(t.speed_rpm, 500, 5);
  EXPECT_GT(t.im_A, 0.5);
  EXPECT_NEAR(t.udc_V, 425, 10);
  drivers::LoadTelemetry l;
  ASSERT_FALSE(bench.load().read(l));
  EXPECT_NEAR(l.torque_Nm, 0.5, 0.05);
}

TEST_F(TwinFixture, WatchdogStopsBothDrivesInOrderAndLatchesUntilReset) {
  spin_up(500);
  // The bench stops sending heartbeats: its clock no longer ticks them (plain virtual time).
  const double silent_from = clock.now_s();
  // The last heartbeat went out up to one period (100 ms) before.
  clock.wait_until(silent_from + 0.35);
  EXPECT_EQ(synrm().state, DriveState::running);  // within the 500 ms timeout
  clock.wait_until(silent_from + 0.65);
  const auto stopping = synrm();
  EXPECT_EQ(stopping.state, DriveState::stopping);  // ordered stop, not a trip
  EXPECT_GT(stopping.speed_rpm, 300);
  clock.wait_until(silent_from + 2.0);
  const auto faulted = synrm();
  EXPECT_EQ(faulted.state, DriveState::faulted);
  EXPECT_EQ(faulted.fault, Fault::watchdog);
  EXPECT_LT(std::abs(faulted.speed_rpm), 50);
  drivers::LoadTelemetry l;
  ASSERT_FALSE(bench.load().read(l));
  EXPECT_EQ(l.fault, Fault::watchdog);
  EXPECT_EQ(service.locked([](auto&, TwinSignals& s, auto&) { return s.watchdog_trips(); }), 1u);

  // Heartbeats again: still faulted; enabling is refused with an exception.
  bench.clock().wait_until(clock.now_s() + 1.0);
  EXPECT_EQ(synrm().state, DriveState::faulted);
  EXPECT_EQ(bench.synrm().enable(true), errc::exception_reply);
  // Exception 4 may be transient (a busy firmware task, a lossy line): the bench repeats it within
  // its retry policy, and the refusal still comes through as the answer.
  const auto tries = 1u + static_cast<unsigned>(drivers::RetryPolicy{}.max_retries);
  EXPECT_EQ(bus.stats().exceptions_by_code[modbus::kServerDeviceFailure], tries);
  ASSERT_FALSE(bench.synrm().reset_fault());
  ASSERT_FALSE(bench.load().reset_fault());
  const auto reset = synrm();
  EXPECT_EQ(reset.state, DriveState::disabled);
  EXPECT_EQ(reset.fault, Fault::none);
}

TEST_F(TwinFixture, NoWatchdogWhileDisabled) {
  clock.wait_until(5.0);  // no heartbeat at all, drives never enabled
  EXPECT_EQ(synrm().state, DriveState::disabled);
  EXPECT_EQ(synrm().fault, Fault::none);
}

TEST_F(TwinFixture, OneWindowOnAllThreeDevices) {
  spin_up(500);
  ASSERT_FALSE(bench.trigger().open_window(0.5));
  EXPECT_FALSE(bench.trigger().window_closed());
  EXPECT_EQ(bench.trigger().open_window(0.5), errc::busy);
  while (!bench.trigger().window_closed()) bench.clock().wait_until(clock.now_s() + 0.01);
  drivers::SynrmWindow w;
  drivers::LoadWindow lw;
  drivers::MeterReading m;
  ASSERT_FALSE(bench.synrm().read_window(w));
  ASSERT_FALSE(bench.load().read_window(lw));
  ASSERT_FALSE(bench.meter().read(m));
  EXPECT_EQ(w.samples, 5000u);
  EXPECT_EQ(lw.samples, 5000u);  // the same periods: one trigger
  EXPECT_NEAR(m.gate_s, 0.5, 1e-6);
  EXPECT_NEAR(w.speed_meas_rpm, 500, 2);
  EXPECT_GT(m.idcm_A, 0.05);
  const auto seq = [&](DeviceKind k) {
    return service.locked([k](auto&, TwinSignals& s, auto&) { return s.window(k); });
  };
  for (auto k : drivers::kDeviceKinds) {
    EXPECT_EQ(seq(k).status, 2);
    EXPECT_EQ(seq(k).sequence, 1);
  }
}

// Through the register map a window reports which estimator fields it has, as the in-process
// drive does with empty fields: EKF-BASIC estimates Ld and Lq but not Rs, EEMF-CONST none of them.
// Read as numbers alone, the missing ones arrived as 0 H and 0 ohm.
TEST_F(TwinFixture, TheWindowSaysWhichEstimatorFieldsItHas) {
  struct Case {
    drivers::Estimator e;
    drivers::Pwm pwm;
    bool inductances;
  };
  for (const Case c : {Case{drivers::Estimator::ekf_basic, drivers::Pwm::aspwm, true},
                       Case{drivers::Estimator::eemf_const, drivers::Pwm::capwm, false}}) {
    const std::string at(drivers::name(c.e));
    ASSERT_FALSE(bench.synrm().enable(false)) << at;
    bench.clock().wait_until(clock.now_s() + 2.0);
    ASSERT_FALSE(bench.synrm().set_pwm(c.pwm)) << at;
    ASSERT_FALSE(bench.synrm().set_estimator(c.e)) << at;
    spin_up(700);
    bench.clock().wait_until(clock.now_s() + 1.0);
    ASSERT_FALSE(bench.trigger().open_window(0.5)) << at;
    while (!bench.trigger().window_closed()) bench.clock().wait_until(clock.now_s() + 0.01);
    drivers::SynrmWindow w;
    ASSERT_FALSE(bench.synrm().read_window(w)) << at;
    ASSERT_TRUE(w.pos_err_mean_deg && w.pos_err_min_deg && w.pos_err_max_deg && w.speed_err_rpm) << at;
    EXPECT_LT(std::fabs(*w.pos_err_mean_deg), 20.0) << at;
    EXPECT_EQ(w.ld_est_H.has_value(), c.inductances) << at;
    EXPECT_EQ(w.lq_est_H.has_value(), c.inductances) << at;
    if (w.ld_est_H) {
      EXPECT_GT(*w.ld_est_H, 0.1) << at;
    }
    EXPECT_FALSE(w.rs_est_ohm) << at << ": " << w.rs_est_ohm.value_or(0);
  }
}

TEST_F(TwinFixture, WindowStartedTwiceOnOneDeviceIsBusy) {
  std::uint8_t reply[modbus::kMaxPdu];
  const std::uint8_t start[] = {modbus::kWriteSingleCoil, 0, 2, 0xFF, 0x00};
  EXPECT_EQ(service.handle(1, start, reply), 5u);
  EXPECT_EQ(service.handle(1, start, reply), 2u);
  EXPECT_EQ(reply[1], modbus::kServerDeviceBusy);
  EXPECT_EQ(service.handle(3, start, reply), 5u);  // another device joins
}

TEST_F(TwinFixture, TheEstimatorChangesOnlyWithTheGatesOff) {
  spin_up(300);
  EXPECT_EQ(bench.synrm().set_estimator(drivers::Estimator::hfi), errc::exception_reply);
  // Busy is repeated within the retry policy (idempotent write), then reported.
  EXPECT_EQ(bus.stats().exceptions_by_code[modbus::kServerDeviceBusy],
            1u + static_cast<unsigned>(drivers::RetryPolicy{}.max_retries));
}

TEST_F(TwinFixture, AStuckSequenceNeverYieldsResults) {
  ASSERT_FALSE(service.locked([](auto&, auto&, RegisterServer& s) { return s.stick(3, "gate_sequence"); }));
  spin_up(300);
  ASSERT_FALSE(bench.trigger().open_window(0.2));
  const double start = clock.now_s();
  while (!bench.trigger().window_closed()) bench.clock().wait_until(clock.now_s() + 0.05);
  EXPECT_GT(clock.now_s() - start, 5.0);  // waited out the margin
  drivers::MeterReading m;
  EXPECT_EQ(bench.meter().read(m), errc::timeout);
  drivers::SynrmWindow w;
  EXPECT_FALSE(bench.synrm().read_window(w));  // the others closed normally
}

}  // namespace
}  // namespace synbench::emulator
