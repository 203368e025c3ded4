// The point procedure on the twin: phases, settle time, unstable and faulted points, stop order.
#include "bench/point_procedure.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "emulator/twin_bench.hpp"
#include "tests/bench/fixed_angle_drive.hpp"

namespace synbench::bench {
namespace {

PointRequest request(double speed, double load, double angle) {
  PointRequest r;
  r.speed_rpm = speed;
  r.load_Nm = load;
  r.angle_deg = angle;
  return r;
}

TEST(PointProcedure, MeasuresSettlesAndEndsStopped) {
  emulator::TwinBench bench{emulator::TwinConfig{}};
  const auto p = run_point(bench.devices(), bench.clock(), request(700, 2.5, 52), PointOptions{});
  ASSERT_EQ(p.phase(), PointPhase::done) << p.error();
  ASSERT_TRUE(p.has_record());
  const auto& r = p.record();
  EXPECT_FALSE(r.unstable);
  EXPECT_FALSE(r.fault);
  // Spin-up at 1000 rpm/s, load at 10 N m/s, at least 0.5 s settling: 1.2 s at the very least.
  EXPECT_GT(r.settle_s, 1.2);
  EXPECT_LT(r.settle_s, 6.0);
  // Ordered stop: load torque gone, shaft (nearly) still, both drives disabled.
  const auto snap = bench.twin().snapshot();
  EXPECT_LT(snap.speed_rpm, 25.0);
  EXPECT_NEAR(snap.load_torque_Nm, 0.0, 0.01);
  EXPECT_EQ(bench.twin().synrm_drive().state(), drivers::DriveState::disabled);
}

TEST(PointProcedure, RecordsTheCurrentAngleTheDriveRanAt) {
  emulator::TwinBench bench{emulator::TwinConfig{}};
  const auto p = run_point(bench.devices(), bench.clock(), request(700, 2.5, 62), PointOptions{});
  ASSERT_TRUE(p.has_record()) << p.error();
  const auto& r = p.record();
  EXPECT_EQ(r.angle_deg, 62.0);
  ASSERT_TRUE(r.angle_meas_deg);
  EXPECT_NEAR(*r.angle_meas_deg, 62.0, 0.5) << "the current controller tracks the angle reference";
  EXPECT_FALSE(r.angle_off);
}

TEST(PointProcedure, FlagsADriveThatDidNotRunAtTheRequestedAngle) {
  // The drive holds 45 deg whatever it is sent: the point is measured (its powers are true for
  // 45 deg) and stored with both angles and the warning.
  emulator::TwinBench bench{emulator::TwinConfig{}};
  testing::FixedAngleDrive deaf(*bench.devices().synrm, 45.0);
  auto devices = bench.devices();
  devices.synrm = &deaf;
  const auto p = run_point(devices, bench.clock(), request(700, 2.5, 62), PointOptions{});
  ASSERT_EQ(p.phase(), PointPhase::done) << p.error();
  const auto& r = p.record();
  EXPECT_EQ(r.angle_deg, 62.0);
  EXPECT_NEAR(r.angle_meas_deg.value_or(0.0), 45.0, 0.5);
  EXPECT_TRUE(r.angle_off);
  EXPECT_FALSE(r.voltage_limited);
}

TEST(PointProcedure, AnUnsettledPointIsMeasuredAndFlaggedNotDropped) {
  emulator::TwinBench bench{emulator::TwinConfig{}};
  PointOptions opt;
  opt.gate.speed_band_rpm = 1e-6;  // unreachable
  opt.settle_timeout_s = 1.0;
  const auto p = run_point(bench.devices(), bench.clock(), request(500, 1.0, 56), opt);
  ASSERT_TRUE(p.has_record());
  EXPECT_TRUE(p.record().unstable);
  EXPECT_GT(p.record().pdcm_W, 0.0);
}

TEST(PointProcedure, AFaultEndsThePointInTheOrderedStopAndIsRecorded) {
  emulator::TwinConfig cfg;
  cfg.firmware.overtemp_trip_C = 50.5;
  cfg.thermal.initial_C = 50.4;
  cfg.thermal.capacity_J_per_K = 20;  // heats in seconds
  emulator::TwinBench bench(cfg);
  const auto p = run_point(bench.devices(), bench.clock(), request(900, 3.5, 56), PointOptions{});
  EXPECT_EQ(p.phase(), PointPhase::failed);
  EXPECT_NE(p.error().find("overtemperature"), std::string::npos) << p.error();
  EXPECT_EQ(p.record().fault.value_or(""), "overtemperature");
  EXPECT_NEAR(bench.twin().snapshot().load_torque_Nm, 0.0, 0.01);
  EXPECT_EQ(bench.twin().synrm_drive().state(), drivers::DriveState::faulted) << "latched";
}

TEST(PointProcedure, RefusesToStartOnALatchedFault) {
  emulator::TwinBench bench{emulator::TwinConfig{}};
  bench.twin().synrm_drive().trip(drivers::Fault::estop);
  const auto p = run_point(bench.devices(), bench.clock(), request(500, 1.0, 56), PointOptions{});
  EXPECT_EQ(p.phase(), PointPhase::failed);
  EXPECT_FALSE(p.has_record());
  EXPECT_NE(p.error().find("reset it first"), std::string::npos) << p.error();
}

}  // namespace
}  // namespace synbench::bench

namespace synbench::bench {
namespace {

TEST(PointProcedure, ChainedPointsRetargetARunningBenchAndAgreeWithStandalone) {
  emulator::TwinBench bench{emulator::TwinConfig{}};
  PointOptions first;
  first.ordered_stop_after = false;
  const auto a = run_point(bench.devices(), bench.clock(), request(700, 2.5, 52), first);
  ASSERT_EQ(a.phase(), PointPhase::done) << a.error();
  PointOptions next = first;
  next.continue_running = true;
  const auto b = run_point(bench.devices(), bench.clock(), request(700, 2.5, 60), next);
  ASSERT_EQ(b.phase(), PointPhase::done) << b.error();
  EXPECT_LT(b.record().settle_s, a.record().settle_s) << "no spin-up between chained points";

  emulator::TwinBench fresh{emulator::TwinConfig{}};
  const auto alone = run_point(fresh.devices(), fresh.clock(), request(700, 2.5, 60), PointOptions{});
  EXPECT_NEAR(b.record().pdcm_W, alone.record().pdcm_W, 0.5);
  EXPECT_NEAR(b.record().im_A, alone.record().im_A, 0.005);
}

TEST(PointProcedure, ThermalPreconditionWarmsAColdMachineBeforeMeasuring) {
  emulator::TwinConfig cfg;
  cfg.thermal.initial_C = 38.0;
  cfg.thermal.capacity_J_per_K = 400.0;  // ten times faster than the real winding
  emulator::TwinBench bench(cfg);
  PointOptions opt;
  opt.thermal = PointOptions::Thermal{};
  const auto p = run_point(bench.devices(), bench.clock(), request(700, 1.0, 56), opt);
  ASSERT_EQ(p.phase(), PointPhase::done) << p.error();
  EXPECT_FALSE(p.record().unstable);
  ASSERT_TRUE(p.record().temp_C);
  EXPECT_NEAR(*p.record().temp_C, 50.0, 5.0);
  EXPECT_GT(*p.record().temp_C, 47.0);
  EXPECT_GT(p.record().settle_s, 10.0) << "it waited for the winding to warm";
  EXPECT_NEAR(p.record().load_Nm, 1.0, 1e-12);
  ASSERT_TRUE(p.record().truth);
  EXPECT_NEAR(p.record().pm_W, p.record().truth->pm_W, 0.01 * p.record().truth->pm_W)
      << "measured at the point's own load, not the warm-up load";
}

}  // namespace
}  // namespace synbench::bench

namespace synbench::bench {
namespace {

// A drive that cannot hold the speed (here a braking torque beyond what the SynRM's current limit
// gives; on the bench, a sensorless observer slipped off the rotor) is measured at once and
// flagged, not left to wait out the gate's timeout at a stalled shaft.
TEST(PointProcedure, ALostSpeedIsMeasuredAtOnceAndReported) {
  emulator::TwinConfig cfg;
  cfg.firmware.current_limit_A = 2.0;  // about 2 N m at most, against a 4 N m brake
  emulator::TwinBench bench{cfg};
  PointOptions opt;
  opt.settle_timeout_s = 30.0;
  const auto p = run_point(bench.devices(), bench.clock(), request(500, 4.0, 56), opt);
  ASSERT_EQ(p.phase(), PointPhase::done) << p.error();
  ASSERT_TRUE(p.has_record());
  EXPECT_TRUE(p.speed_lost());
  EXPECT_TRUE(p.record().unstable);
  EXPECT_FALSE(p.record().fault);
  EXPECT_LT(p.record().speed_meas_rpm, 400.0);
  // Lost after 1 s off by more than 100 rpm (20 % of 500): far sooner than the 30 s timeout.
  EXPECT_LT(p.record().settle_s, 8.0);
  std::printf("lost speed: %.1f rpm measured, settle %.2f s\n", p.record().speed_meas_rpm,
              p.record().settle_s);
}

TEST(PointProcedure, AHeldSpeedIsNotReportedLost) {
  emulator::TwinBench bench{emulator::TwinConfig{}};
  const auto p = run_point(bench.devices(), bench.clock(), request(500, 3.5, 56), PointOptions{});
  ASSERT_TRUE(p.has_record());
  EXPECT_FALSE(p.speed_lost());
  EXPECT_FALSE(p.record().unstable);
}

}  // namespace
}  // namespace synbench::bench

namespace synbench::bench {
namespace {

// Time the load torque takes from 0.1 N m to 2.9 N m on its way to 3 N m.
double load_rise_s(double ramp_Nm_per_s) {
  emulator::TwinBench bench{emulator::TwinConfig{}};
  PointOptions opt;
  opt.load_ramp_Nm_per_s = ramp_Nm_per_s;
  PointProcedure p(bench.devices(), request(700, 3.0, 52), opt);
  double t = 0, t_low = -1, t_high = -1;
  while (!p.finished() && t < 60 && t_high < 0) {
    t += opt.tick_s;
    bench.clock().wait_until(t);
    p.tick(t);
    drivers::LoadTelemetry lt;
    EXPECT_FALSE(bench.devices().load->read(lt));
    if (t_low < 0 && lt.torque_Nm > 0.1) t_low = t;
    if (t_high < 0 && lt.torque_Nm > 2.9) t_high = t;
  }
  EXPECT_GT(t_low, 0);
  EXPECT_GT(t_high, 0);
  return t_high - t_low;
}

// The bench moves the load setpoint at its ramp (a sensorless observer must follow the shaft's
// deceleration); with the ramp off the load drive's own 10 N m/s rules.
TEST(PointProcedure, RampsTheLoadTorqueAtItsRate) {
  const double ramped = load_rise_s(2.0), stepped = load_rise_s(0.0);
  std::printf("0.1 -> 2.9 N m: %.2f s at 2 N m/s, %.2f s stepped\n", ramped, stepped);
  EXPECT_NEAR(ramped, 2.8 / 2.0, 0.15);
  EXPECT_LT(stepped, 0.5);
}

}  // namespace
}  // namespace synbench::bench

namespace synbench::bench {
namespace {

struct StartAngles {
  double loading_deg = 0;   // the current angle (controller frame) while the load comes
  double measured_deg = 0;  // in the window
  bool lock_lost = false;
};

StartAngles start_angles(drivers::Estimator e, double angle_deg) {
  emulator::TwinBench bench{emulator::TwinConfig{}};
  PointRequest req = request(700, 2.0, angle_deg);
  req.estimator = e;
  PointOptions opt;
  opt.settle_timeout_s = 5.0;
  PointProcedure p(bench.devices(), req, opt);
  StartAngles out;
  double t = 0;
  while (!p.finished() && t < 60) {
    t += opt.tick_s;
    bench.clock().wait_until(t);
    p.tick(t);
    drivers::SynrmTelemetry st;
    EXPECT_FALSE(bench.devices().synrm->read(st));
    drivers::LoadTelemetry lt;
    EXPECT_FALSE(bench.devices().load->read(lt));
    // Half-way up the load ramp, long after the speed-up.
    if (p.phase() == PointPhase::load_up && lt.torque_Nm > 1.0 && out.loading_deg == 0)
      out.loading_deg = std::atan2(st.iq_A, st.id_A) * 180.0 / 3.14159265358979323846;
  }
  EXPECT_EQ(p.phase(), PointPhase::done) << p.error();
  EXPECT_TRUE(p.has_record());
  const auto& r = p.record();
  out.measured_deg = r.angle_meas_deg.value_or(-1.0);
  EXPECT_FALSE(r.angle_off) << "measured " << out.measured_deg << " deg for " << angle_deg;
  out.lock_lost = r.lock_lost;
  return out;
}

// A sensorless point from rest spins up and takes its load at the start angle (45 deg) and is
// measured at its own; the encoder, and a point below the start angle, keep their own angle
// throughout.
TEST(PointProcedure, ASensorlessPointTakesItsLoadAtTheStartAngleAndIsMeasuredAtItsOwn) {
  const auto konst = start_angles(drivers::Estimator::eemf_const, 70.0);
  const auto enc = start_angles(drivers::Estimator::encoder, 70.0);
  const auto low = start_angles(drivers::Estimator::eemf_const, 40.0);
  std::printf("current angle while loading / in the window: EEMF-CONST 70 deg %.1f / %.1f, encoder "
              "70 deg %.1f / %.1f, EEMF-CONST 40 deg %.1f / %.1f\n",
              konst.loading_deg, konst.measured_deg, enc.loading_deg, enc.measured_deg, low.loading_deg,
              low.measured_deg);
  EXPECT_NEAR(konst.loading_deg, 45.0, 2.0);
  EXPECT_NEAR(konst.measured_deg, 70.0, 1.0);
  EXPECT_FALSE(konst.lock_lost);
  EXPECT_NEAR(enc.loading_deg, 70.0, 2.0);
  EXPECT_NEAR(enc.measured_deg, 70.0, 1.0);
  EXPECT_NEAR(low.loading_deg, 40.0, 2.0);
  EXPECT_NEAR(low.measured_deg, 40.0, 1.0);
}

// Spun up unloaded at its own angle, EEMF-CONST slips during the speed overshoot (its EEMF is a
// few volts there) and the point is lost before its load arrives: at 700 rpm, 58 deg and at
// 500 rpm, 40 deg (where only the early load helps, the angle being below the start angle).
// The sensorless start holds both, at each of five noise seeds. The plain start's slip is the
// motivation, and over seeds it is a chance: at 500 rpm, 40 deg it slipped at all five, at
// 700 rpm, 58 deg at seeds 1 and 4 only (2026-12-03), so it is asserted as "at some seed".
TEST(PointProcedure, TheSensorlessStartKeepsEemfConstInLock) {
  struct Case {
    double speed_rpm, load_Nm, angle_deg;
  };
  for (const Case c : {Case{700, 2.0, 58}, Case{500, 1.5, 40}})
    for (const bool plain : {true, false}) {
      int lost = 0;
      std::string lost_at;
      for (const int seed : {1, 2, 3, 4, 5}) {
        emulator::TwinConfig cfg;
        cfg.sim.seed_int = seed;
        emulator::TwinBench bench{cfg};
        PointRequest req = request(c.speed_rpm, c.load_Nm, c.angle_deg);
        req.estimator = drivers::Estimator::eemf_const;
        PointOptions opt;
        opt.settle_timeout_s = 5.0;
        if (plain) {
          opt.sensorless_start_angle_deg = 0;
          opt.sensorless_load_at_speed_fraction = 1.0;
        }
        const auto p = run_point(bench.devices(), bench.clock(), req, opt);
        const std::string at = std::to_string(c.speed_rpm) + " rpm " + std::to_string(c.angle_deg) + " deg, " +
                               (plain ? "plain start" : "sensorless start") + ", seed " + std::to_string(seed);
        ASSERT_TRUE(p.has_record()) << at << ": " << p.error();
        EXPECT_FALSE(p.record().fault) << at;
        if (p.record().lock_lost) {
          ++lost;
          lost_at += " " + std::to_string(seed);
        }
      }
      std::printf("EEMF-CONST %.0f rpm %.0f deg, %s: lock lost at %d of 5 seeds (%s)\n", c.speed_rpm, c.angle_deg,
                  plain ? "plain start" : "sensorless start", lost, lost_at.c_str());
      if (plain)
        EXPECT_GE(lost, 1) << c.speed_rpm << " rpm: the plain start never slipped, the sensorless start is moot";
      else
        EXPECT_EQ(lost, 0) << c.speed_rpm << " rpm: the sensorless start lost the rotor at seeds" << lost_at;
    }
}

}  // namespace
}  // namespace synbench::bench

namespace synbench::bench {
namespace {

// Chained as a sweep runs them: a point the drive's lock guard took to the encoder (EEMF-LUT at
// 500 rpm, 2 N m, 76 deg) and the next one (2.5 N m, 40 deg). The drive holds the trip until
// the new setpoints are reached; that held trip is not the next point's, which is measured in
// lock on the fresh estimator. On the EEMF's direction alone (the thesis' observer), which loses
// the rotor there; the default vector error holds it.
TEST(PointProcedure, ATripHeldFromThePreviousPointIsNotTheNextPointsLockLoss) {
  emulator::TwinConfig cfg;
  cfg.estimators.eemf.error_signal = emulator::EemfErrorSignal::direction;
  emulator::TwinBench bench{cfg};
  PointOptions opt;
  opt.ordered_stop_after = false;
  opt.continue_running = true;
  opt.settle_timeout_s = 5.0;
  const auto chained = [&](double load_Nm, double angle_deg) {
    PointRequest req = request(500, load_Nm, angle_deg);
    req.estimator = drivers::Estimator::eemf_lut;
    const auto p = run_point(bench.devices(), bench.clock(), req, opt);
    EXPECT_TRUE(p.has_record()) << p.error();
    return p.record();
  };
  const auto before = chained(2.0, 56.0);
  const auto lost = chained(2.0, 76.0);
  const auto next = chained(2.5, 40.0);
  EXPECT_FALSE(before.lock_lost);
  ASSERT_TRUE(lost.lock_lost) << "EEMF-LUT held 76 deg: the test needs a lost point";
  EXPECT_FALSE(next.lock_lost);
  EXPECT_FALSE(next.fault);
  ASSERT_TRUE(next.pos_err_mean_deg);
  EXPECT_LT(std::fabs(*next.pos_err_mean_deg), 2.0);
}

}  // namespace
}  // namespace synbench::bench
