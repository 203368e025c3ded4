// The ordered stop (bench/ordered_stop.hpp) on the twin: the load torque goes first while the
// SynRM holds its speed, then the speed, then both drives are disabled; a load that does not
// answer and a SynRM that does not report are bounded by their timeouts.
#include "bench/ordered_stop.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include "emulator/twin_bench.hpp"

namespace synbench::bench {
namespace {

struct Running {
  emulator::TwinBench bench{emulator::TwinConfig{}};
  double t = 0;

  Running() {
    auto d = bench.devices();
    EXPECT_FALSE(d.load->enable(true));
    EXPECT_FALSE(d.synrm->set_angle_deg(50));
    EXPECT_FALSE(d.synrm->set_speed_rpm(700));
    EXPECT_FALSE(d.synrm->enable(true));
    advance(1.5);
    EXPECT_FALSE(d.load->set_torque_Nm(2.0));
    advance(1.5);
  }
  void advance(double s) {
    for (const double end = t + s; t < end - 1e-9;) {
      t += 0.01;
      bench.clock().wait_until(t);
    }
  }
  std::optional<drivers::SynrmTelemetry> synrm() {
    drivers::SynrmTelemetry s;
    if (bench.devices().synrm->read(s)) return std::nullopt;
    return s;
  }
  std::optional<drivers::LoadTelemetry> load() {
    drivers::LoadTelemetry l;
    if (bench.devices().load->read(l)) return std::nullopt;
    return l;
  }
  bool drives_off() {
    using drivers::DriveState;
    const auto s = bench.twin().synrm_drive().state();
    return s != DriveState::running && s != DriveState::stopping &&
           bench.twin().load_drive().telemetry().state != DriveState::running;
  }
};

TEST(OrderedStop, TheLoadGoesFirstAtItsRampThenTheSpeedThenBothDrives) {
  Running r;
  ASSERT_NEAR(r.bench.twin().snapshot().speed_rpm, 700.0, 20.0);
  OrderedStop stop;
  OrderedStopOptions opt;
  opt.load_ramp_Nm_per_s = 2.0;
  stop.begin(r.bench.devices(), opt, r.t, 2.0);
  double load_gone_at = -1, done_at = -1, lowest_speed_while_loaded = 1e9;
  while (r.t < 30.0 && done_at < 0) {
    r.advance(0.01);
    const auto s = r.synrm();
    const auto l = r.load();
    ASSERT_TRUE(s && l);
    if (std::fabs(l->torque_Nm) > 0.05)
      lowest_speed_while_loaded = std::min(lowest_speed_while_loaded, s->speed_rpm);
    else if (load_gone_at < 0)
      load_gone_at = r.t;
    if (stop.tick(r.t, s, l)) done_at = r.t;
  }
  ASSERT_GT(done_at, 0) << "never done";
  EXPECT_FALSE(stop.timed_out());
  EXPECT_EQ(stop.step(), StopStep::done);
  // 2 N m at 2 N m/s: a second, the speed held meanwhile.
  EXPECT_NEAR(load_gone_at - 3.0, 1.0, 0.15);
  EXPECT_GT(lowest_speed_while_loaded, 650.0);
  // 700 rpm at the drive's 1000 rpm/s ramp after the load.
  EXPECT_GT(done_at - load_gone_at, 0.6);
  // Below 20 rpm as the drive reports it (its telemetry filtered over 50 ms), the shaft at most
  // a few tens of rpm behind.
  EXPECT_LT(std::fabs(r.bench.twin().snapshot().speed_rpm), 50.0);
  EXPECT_TRUE(r.drives_off());
}

TEST(OrderedStop, CoastingDisablesAsSoonAsTheLoadIsGone) {
  Running r;
  OrderedStop stop;
  OrderedStopOptions opt;
  opt.coast = true;
  stop.begin(r.bench.devices(), opt, r.t, 2.0);
  double done_at = -1;
  const double t0 = r.t;
  while (r.t < t0 + 5.0 && done_at < 0) {
    r.advance(0.01);
    if (stop.tick(r.t, r.synrm(), r.load())) done_at = r.t;
  }
  ASSERT_GT(done_at, 0);
  // At the load drive's own 10 N m/s: 0.2 s, and the shaft still turning.
  EXPECT_LT(done_at - t0, 0.5);
  EXPECT_TRUE(r.drives_off());
  EXPECT_GT(r.bench.twin().snapshot().speed_rpm, 400.0);
}

TEST(OrderedStop, UnansweredStepsEndOnTheirTimeouts) {
  Running r;
  OrderedStop stop;
  OrderedStopOptions opt;
  opt.load_timeout_s = 0.5;
  opt.speed_timeout_s = 2.0;
  stop.begin(r.bench.devices(), opt, r.t, 2.0);
  const double t0 = r.t;
  // No load telemetry: the load is never seen gone; it is disabled at its timeout and the speed
  // comes down anyway. No SynRM telemetry: the speed step ends on its own timeout.
  double speed_step_at = -1, done_at = -1;
  while (r.t < t0 + 10.0 && done_at < 0) {
    r.advance(0.01);
    if (stop.tick(r.t, std::nullopt, std::nullopt)) done_at = r.t;
    if (speed_step_at < 0 && stop.step() == StopStep::speed) speed_step_at = r.t;
  }
  EXPECT_NEAR(speed_step_at - t0, 0.5, 0.02);
  EXPECT_NEAR(done_at - speed_step_at, 2.0, 0.02);
  EXPECT_TRUE(stop.timed_out());
  EXPECT_TRUE(r.drives_off());
}

}  // namespace
}  // namespace synbench::bench
