// The sweep engine on the twin: completes a plan in order, stores every point once, resumes at
// the missing points, stops the drive to switch configuration, pauses, aborts, and ends faulted
// when the supervisor trips.
#include "bench/sweep_engine.hpp"

#include <gtest/gtest.h>
#include "drivers/json.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <vector>

#include "drivers/error.hpp"
#include "emulator/twin_bench.hpp"
#include "tests/bench/fixed_angle_drive.hpp"
#include "bench/analysis.hpp"
#include "bench/sweep_outcome.hpp"

namespace synbench::bench {
namespace {

struct VectorSink : SweepSink {
  std::vector<std::pair<std::size_t, PointRecord>> points;
  std::vector<std::string> events;
  std::size_t fail_at = static_cast<std::size_t>(-1);
  std::error_code store_point(std::size_t index, const PointRecord& r) override {
    if (points.size() == fail_at) return make_error_code(errc::disconnected);
    points.emplace_back(index, r);
    return {};
  }
  void event(const std::string& kind, const std::string& message) override {
    events.push_back(kind + ": " + message);
  }
};

SweepPlan plan_from(const char* json) {
  auto r = parse_sweep_plan(synbench::Json::parse(json));
  EXPECT_TRUE(r.errors.empty()) << (r.errors.empty() ? "" : to_string(r.errors.front()));
  return *r.plan;
}

const char* kSmall = R"({
  "name": "small",
  "dimensions": {"speed_rpm": [500, 700], "load_Nm": [1.0, 2.0], "angle_deg": [50, 56, 62]},
  "window_s": 0.5,
  "thermal": {"enabled": false}
})";

struct TwinRun {
  TwinRun() = default;
  explicit TwinRun(const emulator::TwinConfig& config) : bench{config} {}
  emulator::TwinBench bench{emulator::TwinConfig{}};
  SafetySupervisor sup{bench.devices(), SafetyLimits{}};
  double t = 0;
  template <class F>
  void until(SweepEngine& e, double max_s, F&& hook) {
    while (!e.finished() && t < max_s) {
      t += 0.01;
      bench.clock().wait_until(t);
      sup.tick(t);
      e.tick(t);
      hook(t);
    }
  }
  void until(SweepEngine& e, double max_s) {
    until(e, max_s, [](double) {});
  }
};

TEST(SweepEngine, CompletesAGridInOrderAndEndsStopped) {
  TwinRun run;
  VectorSink sink;
  SweepEngine e(run.bench.devices(), run.sup, plan_from(kSmall), {}, sink);
  run.until(e, 600);
  ASSERT_EQ(e.state(), SweepState::completed) << e.error();
  ASSERT_EQ(sink.points.size(), 12u);
  for (std::size_t i = 0; i < 12; ++i) EXPECT_EQ(sink.points[i].first, i);
  const auto& first = sink.points.front().second;
  EXPECT_EQ(first.speed_rpm, 500);
  EXPECT_EQ(first.load_Nm, 1.0);
  EXPECT_EQ(first.angle_deg, 50);
  EXPECT_EQ(sink.points.back().second.angle_deg, 62);
  for (const auto& [i, r] : sink.points) {
    EXPECT_NEAR(r.speed_meas_rpm, r.speed_rpm, 1.0) << i;
    EXPECT_GT(r.pdcm_W, r.pm_W) << i;
    EXPECT_FALSE(r.unstable) << i;
    // The drive ran at the requested angle, not only the record says so.
    ASSERT_TRUE(r.angle_meas_deg) << i;
    EXPECT_NEAR(*r.angle_meas_deg, r.angle_deg, 0.5) << i;
    EXPECT_FALSE(r.angle_off) << i;
  }
  EXPECT_TRUE(std::none_of(sink.events.begin(), sink.events.end(),
                           [](const std::string& ev) { return ev.find("angle_off") != std::string::npos; }));
  EXPECT_EQ(run.bench.twin().synrm_drive().state(), drivers::DriveState::disabled);
  run.bench.clock().wait_until(run.t + 5.0);  // disabled below 20 rpm, the shaft coasts out
  EXPECT_LT(std::fabs(run.bench.twin().snapshot().speed_rpm), 5.0);
  // Chained points are quicker than from standstill.
  EXPECT_LT(sink.points[1].second.settle_s, sink.points[0].second.settle_s);
}

TEST(SweepEngine, StoresAndLogsAPointTheDriveRanAtAnotherAngle) {
  TwinRun run;
  testing::FixedAngleDrive deaf(*run.bench.devices().synrm, 45.0);
  auto devices = run.bench.devices();
  devices.synrm = &deaf;
  VectorSink sink;
  SweepEngine e(devices, run.sup, plan_from(R"({
    "dimensions": {"speed_rpm": [700], "load_Nm": [2.0], "angle_deg": [45, 62]},
    "window_s": 0.5, "thermal": {"enabled": false}})"), {}, sink);
  run.until(e, 120);
  ASSERT_EQ(e.state(), SweepState::completed) << e.error();
  ASSERT_EQ(sink.points.size(), 2u);
  EXPECT_FALSE(sink.points[0].second.angle_off) << "45 deg was what it ran at";
  EXPECT_TRUE(sink.points[1].second.angle_off);
  const auto logged = std::count_if(sink.events.begin(), sink.events.end(), [](const std::string& ev) {
    return ev.find("point 1: the drive ran at a current angle of 45.0 deg, not the requested 62.0 deg") !=
           std::string::npos;
  });
  EXPECT_EQ(logged, 1);
}

TEST(SweepEngine, ResumesAtTheMissingPointsOnly) {
  TwinRun run;
  VectorSink first;
  first.fail_at = 5;  // the "crash": storing the sixth point fails
  SweepEngine e1(run.bench.devices(), run.sup, plan_from(kSmall), {}, first);
  run.until(e1, 600);
  EXPECT_EQ(e1.state(), SweepState::faulted);
  ASSERT_EQ(first.points.size(), 5u);

  TwinRun again;
  std::map<std::size_t, PointRecord> stored(first.points.begin(), first.points.end());
  VectorSink second;
  SweepEngine e2(again.bench.devices(), again.sup, plan_from(kSmall), stored, second);
  again.until(e2, 600);
  ASSERT_EQ(e2.state(), SweepState::completed) << e2.error();
  ASSERT_EQ(second.points.size(), 7u);
  for (std::size_t i = 0; i < 7; ++i) EXPECT_EQ(second.points[i].first, i + 5);
}

TEST(SweepEngine, StopsTheDriveToSwitchConfiguration) {
  TwinRun run;
  VectorSink sink;
  SweepEngine e(run.bench.devices(), run.sup, plan_from(R"({
    "dimensions": {"speed_rpm": [700], "load_Nm": [2.0], "angle_deg": [56],
                   "configurations": [{"estimator": "encoder", "pwm": "capwm"},
                                      {"estimator": "ekf-basic", "pwm": "aspwm"}]},
    "window_s": 0.5, "thermal": {"enabled": false}})"), {}, sink);
  run.until(e, 600);
  ASSERT_EQ(e.state(), SweepState::completed) << e.error();
  ASSERT_EQ(sink.points.size(), 2u);
  EXPECT_EQ(sink.points[1].second.estimator, drivers::Estimator::ekf_basic);
  ASSERT_TRUE(sink.points[1].second.pos_err_mean_deg);
  EXPECT_LT(std::fabs(*sink.points[1].second.pos_err_mean_deg), 7.5);
  bool switched = false;
  for (const auto& ev : sink.events) switched = switched || ev.find("switch configuration") != std::string::npos;
  EXPECT_TRUE(switched);
}

TEST(SweepEngine, PausesBetweenPointsAndAbortsToAnOrderedStop) {
  TwinRun run;
  VectorSink sink;
  SweepEngine e(run.bench.devices(), run.sup, plan_from(kSmall), {}, sink);
  bool paused_once = false;
  run.until(e, 600, [&](double) {
    if (sink.points.size() == 2 && !paused_once) {
      e.pause();
      paused_once = true;
    }
    if (e.state() == SweepState::paused) {
      EXPECT_EQ(sink.points.size(), 2u);
      if (run.t > 60) e.abort();
    }
  });
  EXPECT_EQ(e.state(), SweepState::aborted);
  EXPECT_EQ(sink.points.size(), 2u);
  EXPECT_EQ(run.bench.twin().synrm_drive().state(), drivers::DriveState::disabled);
  run.bench.clock().wait_until(run.t + 5.0);
  EXPECT_LT(std::fabs(run.bench.twin().snapshot().speed_rpm), 5.0);
}

TEST(SweepEngine, EndsFaultedWhenTheSupervisorTrips) {
  TwinRun run;
  VectorSink sink;
  SweepEngine e(run.bench.devices(), run.sup, plan_from(kSmall), {}, sink);
  run.until(e, 600, [&](double) {
    if (sink.points.size() == 3) run.bench.twin().set_winding_temp_C(115.0);
  });
  EXPECT_EQ(e.state(), SweepState::faulted);
  EXPECT_NE(e.error().find("overtemperature"), std::string::npos) << e.error();
  EXPECT_LE(sink.points.size(), 4u);
  EXPECT_TRUE(run.sup.tripped());
}

namespace synbench::bench {
namespace {

// A point whose drive cannot hold the speed (here the brake exceeds what the SynRM's current
// limit gives; on the bench, a sensorless observer that slipped) is recorded unstable at once,
// logged, and the drives are stopped so that the next point starts from standstill and is
// measured normally; nothing faults.
// HFI started after the drives were stopped to switch configuration: the shaft comes to rest at
// whatever angle the previous configuration left it, and HFI starts from its own zero. Without
// its initial position detection (the carrier running with no torque current for
// estimators.hfi.align_s) the first point of this plan started 58 deg off, drove the shaft
// backwards to -700 rpm and tripped on over-current.
TEST(SweepEngine, HfiFindsTheRotorAfterAConfigurationSwitch) {
  TwinRun run;
  VectorSink sink;
  SweepEngine e(run.bench.devices(), run.sup, plan_from(R"({
    "name": "switch to hfi",
    "preset": "thesis-grid",
    "dimensions": {"speed_rpm": [300], "load_Nm": [3.0, 3.5],
                   "configurations": [{"estimator": "encoder", "pwm": "capwm"}, {"estimator": "hfi", "pwm": "capwm"},
                                      {"estimator": "encoder", "pwm": "aspwm"}]}
  })"), {}, sink);
  run.until(e, 3600);
  ASSERT_EQ(e.state(), SweepState::completed) << e.error();
  ASSERT_EQ(sink.points.size(), 2u * 3u * 19u);
  int hfi = 0, guarded = 0;
  for (const auto& [index, r] : sink.points) {
    if (r.estimator != drivers::Estimator::hfi) continue;
    ++hfi;
    EXPECT_FALSE(r.fault) << index;
    // A point the lock guard ran on the encoder has no position error to check (3.5 N m, 76 deg,
    // the grid's hardest for HFI; the thesis sweep guards it too); the first, after the switch,
    // must hold.
    if (r.lock_lost && hfi > 1) {
      ++guarded;
      continue;
    }
    ASSERT_TRUE(r.pos_err_min_deg && r.pos_err_max_deg) << index;
    EXPECT_LT(*r.pos_err_max_deg - *r.pos_err_min_deg, 90.0) << index << ": out of lock";
  }
  EXPECT_EQ(hfi, 2 * 19);
  EXPECT_LE(guarded, 1);
}

// Between configurations the engine removes the load at the bench's ramp (2 N m/s), as between
// points, not at the load drive's 10 N m/s: removed at once, a sensorless drive at a high current
// angle let the shaft run away into an over-speed trip.
TEST(SweepEngine, StopsToSwitchConfigurationWithTheLoadRamped) {
  TwinRun run;
  VectorSink sink;
  SweepEngine e(run.bench.devices(), run.sup, plan_from(R"({
    "name": "ramped stop",
    "dimensions": {"speed_rpm": [500], "load_Nm": [3.0], "angle_deg": [56],
                   "configurations": [{"estimator": "encoder", "pwm": "capwm"}, {"estimator": "encoder", "pwm": "aspwm"}]},
    "window_s": 0.5,
    "thermal": {"enabled": false}
  })"), {}, sink);
  double last_t = -1, last_torque = 0, fastest_Nm_per_s = 0, stop_fall_s = -1, t_high = -1;
  run.until(e, 300, [&](double t) {
    drivers::LoadTelemetry lt;
    if (run.bench.devices().load->read(lt)) return;
    if (last_t >= 0 && t - last_t > 0)
      fastest_Nm_per_s = std::max(fastest_Nm_per_s, std::fabs(lt.torque_Nm - last_torque) / (t - last_t));
    // After the first point: how long the torque takes from 2.5 N m down to 0.5 N m.
    if (sink.points.size() == 1 && lt.torque_Nm > 2.5) t_high = t;
    if (sink.points.size() == 1 && t_high >= 0 && stop_fall_s < 0 && lt.torque_Nm < 0.5) stop_fall_s = t - t_high;
    last_t = t;
    last_torque = lt.torque_Nm;
  });
  ASSERT_EQ(e.state(), SweepState::completed) << e.error();
  ASSERT_EQ(sink.points.size(), 2u);
  EXPECT_LT(fastest_Nm_per_s, 2.5) << "the load moves at the bench's 2 N m/s everywhere";
  EXPECT_GT(stop_fall_s, 0.9) << "2 N m at 2 N m/s";
}

TEST(SweepEngine, RestartsTheDrivesAfterAPointThatLostTheSpeed) {
  emulator::TwinConfig cfg;
  cfg.firmware.current_limit_A = 1.5;  // about 1.5 N m at most, against a 3.5 N m brake
  TwinRun run{cfg};
  VectorSink sink;
  SweepEngine e(run.bench.devices(), run.sup, plan_from(R"({
    "name": "lost",
    "dimensions": {"speed_rpm": [500], "load_Nm": [3.5, 0.5], "angle_deg": [56]},
    "window_s": 0.5,
    "thermal": {"enabled": false}
  })"), {}, sink);
  run.until(e, 300);
  ASSERT_EQ(e.state(), SweepState::completed) << e.error();
  ASSERT_EQ(sink.points.size(), 2u);
  const auto& lost = sink.points[0].second;
  const auto& next = sink.points[1].second;
  EXPECT_TRUE(lost.unstable);
  EXPECT_FALSE(lost.fault);
  EXPECT_LT(lost.speed_meas_rpm, 400.0);
  EXPECT_LT(lost.settle_s, 8.0) << "measured at once, not after the gate's timeout";
  EXPECT_FALSE(next.unstable);
  EXPECT_NEAR(next.speed_meas_rpm, 500.0, 1.0);
  bool logged = false;
  for (const auto& ev : sink.events)
    logged = logged || ev.find("could not hold 500 rpm") != std::string::npos;
  EXPECT_TRUE(logged);
}

}  // namespace
}  // namespace synbench::bench

// The drive's lock guard (docs/estimators.md): EEMF-RLS at 500 rpm through the thesis grid lost
// the rotor and tripped the drive on over-current after a few dozen points, which ended the
// sweep. Guarded, the points where it lost the rotor are flagged `lock_lost` and the sweep
// completes; the points it holds keep the estimator's own errors.
TEST(SweepEngine, TheLockGuardKeepsAnEemfRlsSweepGoingWhereItTripped) {
  const char* plan = R"({
    "name": "rls at 500 rpm",
    "preset": "thesis-grid",
    "dimensions": {"speed_rpm": [500], "configurations": [{"estimator": "eemf-rls", "pwm": "capwm"}]}
  })";
  auto run_with = [&](double guard_deg, VectorSink& sink) {
    emulator::TwinConfig cfg;
    cfg.firmware.lock_guard_deg = guard_deg;
    TwinRun run{cfg};
    SweepEngine e(run.bench.devices(), run.sup, plan_from(plan), {}, sink);
    run.until(e, 7200);
    return std::make_pair(e.state(), e.error());
  };
  VectorSink unguarded;
  const auto [state_off, error_off] = run_with(0.0, unguarded);
  EXPECT_EQ(state_off, SweepState::faulted);
  EXPECT_NE(error_off.find("overcurrent"), std::string::npos) << error_off;
  EXPECT_LT(unguarded.points.size(), 133u);

  VectorSink guarded;
  const auto [state_on, error_on] = run_with(45.0, guarded);
  ASSERT_EQ(state_on, SweepState::completed) << error_on;
  ASSERT_EQ(guarded.points.size(), 133u);
  int lost = 0, held = 0;
  for (const auto& [index, r] : guarded.points) {
    EXPECT_FALSE(r.fault) << index;
    if (r.lock_lost) {
      ++lost;
      continue;
    }
    ++held;
    ASSERT_TRUE(r.pos_err_mean_deg && r.rs_est_ohm) << index;
    // The RLS' identified inductances are off by tens of percent in closed loop: its means in
    // lock reach 18.5 deg at 500 rpm (docs/estimators.md).
    EXPECT_LT(std::fabs(*r.pos_err_mean_deg), 20.0) << index;
  }
  EXPECT_GT(lost, 0);
  EXPECT_GE(held, 15) << "the light-load points hold, as without the guard";
  std::printf("EEMF-RLS at 500 rpm, guarded: %d of %zu points held, %d on the encoder\n", held,
              guarded.points.size(), lost);
  bool logged = false;
  for (const auto& ev : guarded.events) logged = logged || ev.find("lock guard") != std::string::npos;
  EXPECT_TRUE(logged);
}

// ------------------------------------------------------------ measure until sure

// One point at 700 rpm, 2.5 N m, 56 deg over `window_s`, with an optional precision section.
SweepPlan one_point(double window_s, const std::string& precision) {
  return plan_from((R"({"dimensions": {"speed_rpm": [700], "load_Nm": [2.5], "angle_deg": [56]},
    "thermal": {"enabled": false}, "window_s": )" + std::to_string(window_s) +
                    (precision.empty() ? "" : ", \"precision\": " + precision) + "}")
                       .c_str());
}

std::size_t count_events(const VectorSink& sink, const std::string& what) {
  return static_cast<std::size_t>(std::count_if(sink.events.begin(), sink.events.end(), [&](const std::string& ev) {
    return ev.find(what) != std::string::npos;
  }));
}

TEST(SweepEngine, LengthensAPointsWindowUntilItsPdcmUIsBelowTheTarget) {
  // The point's u over a short window, without a target.
  TwinRun plain_run;
  VectorSink plain;
  SweepEngine e0(plain_run.bench.devices(), plain_run.sup, one_point(0.3, ""), {}, plain);
  plain_run.until(e0, 120);
  ASSERT_EQ(plain.points.size(), 1u);
  ASSERT_TRUE(plain.points[0].second.pdcm_u_repeat_W);
  const double u0 = *plain.points[0].second.pdcm_u_repeat_W;
  EXPECT_NEAR(plain.points[0].second.window_s, 0.3, 0.02);

  // A target 1.6 times below it: about 0.3 x 1.6^2 x 1.2 = 0.92 s predicted.
  const double target = u0 / 1.6;
  char precision[120];
  std::snprintf(precision, sizeof precision, R"({"pdcm_u_repeat_target_W": %.6g, "max_window_s": 4})", target);
  TwinRun run;
  VectorSink sink;
  SweepEngine e(run.bench.devices(), run.sup, one_point(0.3, precision), {}, sink);
  run.until(e, 120);
  ASSERT_EQ(e.state(), SweepState::completed) << e.error();
  ASSERT_EQ(sink.points.size(), 1u) << "only the final record is stored";
  const auto& [index, r] = sink.points[0];
  EXPECT_EQ(index, 0u) << "at the point's own index";
  EXPECT_GE(count_events(sink, "point 0: pdcm_u_repeat_W"), 1u);
  EXPECT_EQ(count_events(sink, "precision target missed"), 0u);
  EXPECT_GT(r.window_s, 0.8);
  EXPECT_LE(r.window_s, 4.0);
  ASSERT_TRUE(r.pdcm_u_repeat_W);
  EXPECT_LE(*r.pdcm_u_repeat_W, target);
  EXPECT_FALSE(r.unstable);
  // The drives kept running: no ordered stop between the windows (one "sweep completed" stop).
  EXPECT_EQ(count_events(sink, "drives stopped"), 0u);
  std::printf("precision: u %.4f W over 0.3 s; target %.4f W reached with %.4f W over %.2f s\n", u0, target,
              *r.pdcm_u_repeat_W, r.window_s);
  for (const auto& ev : sink.events) std::printf("  %s\n", ev.c_str());
  EXPECT_EQ(sweep_outcome(one_point(0.3, precision), {{index, r}}).precision->missed.size(), 0u);

  // A target out of reach within a 1 s cap: stored with what it reached, flagged, never dropped.
  std::snprintf(precision, sizeof precision, R"({"pdcm_u_repeat_target_W": %.6g, "max_window_s": 1})", u0 / 100);
  TwinRun capped_run;
  VectorSink capped;
  const SweepPlan capped_plan = one_point(0.3, precision);
  SweepEngine e2(capped_run.bench.devices(), capped_run.sup, capped_plan, {}, capped);
  capped_run.until(e2, 120);
  ASSERT_EQ(e2.state(), SweepState::completed) << e2.error();
  ASSERT_EQ(capped.points.size(), 1u);
  EXPECT_NEAR(capped.points[0].second.window_s, 1.0, 0.02);
  EXPECT_EQ(count_events(capped, "point 0: precision target missed"), 1u);
  EXPECT_EQ(sweep_outcome(capped_plan, {capped.points[0]}).precision->missed, std::vector<std::size_t>{0});
}

TEST(SweepEngine, AdaptiveSearchMeasuresUntilBothAnglesAreBelowTheTarget) {
  TwinRun run;
  VectorSink sink;
  const SweepPlan plan = plan_from(R"({"mode": "adaptive",
    "dimensions": {"speed_rpm": [300, 700], "load_Nm": [2.5]},
    "adaptive": {"angle_u_target_deg": 0.5, "max_evaluations": 20},
    "window_s": 1, "thermal": {"enabled": false}})");
  SweepEngine e(run.bench.devices(), run.sup, plan, {}, sink);
  run.until(e, 1200);
  ASSERT_EQ(e.state(), SweepState::completed) << e.error();
  std::map<std::size_t, PointRecord> stored(sink.points.begin(), sink.points.end());
  const auto o = sweep_outcome(plan, stored);
  std::printf("%s", to_text(o).c_str());
  ASSERT_EQ(o.curves.size(), 2u);
  std::vector<PointRecord> records;
  for (const auto& [i, r] : sink.points) records.push_back(r);
  const auto analysis = analyze(records);
  ASSERT_EQ(analysis.curves.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    const auto& c = o.curves[k];
    EXPECT_TRUE(c.result.angle_u_target_met) << k;
    EXPECT_LT(c.result.evaluations, 20u) << k;
    ASSERT_TRUE(c.result.mtpa.angle_u_deg && c.result.me.angle_u_deg);
    EXPECT_LE(*c.result.mtpa.angle_u_deg, 0.5);
    EXPECT_LE(*c.result.me.angle_u_deg, 0.5);
    // The analysis on the same points (its three-point refinement, its Monte Carlo).
    const auto& a = analysis.curves[k];
    ASSERT_TRUE(a.mtpa.angle_u_deg && a.me.angle_u_deg);
    std::printf("curve %zu: search MTPA %.2f +/- %.2f, ME %.2f +/- %.2f; analysis MTPA %.2f +/- %.2f, ME %.2f +/- %.2f deg\n",
                k, c.result.mtpa.angle_deg, *c.result.mtpa.angle_u_deg, c.result.me.angle_deg,
                *c.result.me.angle_u_deg, a.mtpa.angle_deg, *a.mtpa.angle_u_deg, a.me.angle_deg, *a.me.angle_u_deg);
    EXPECT_LE(*a.mtpa.angle_u_deg, 0.5) << k;
    EXPECT_LE(*a.me.angle_u_deg, 0.5) << k;
  }
  EXPECT_LT(o.points_used, o.grid_points);

  // The twin's scatter over 1 s puts both angles within a few 0.01 deg from five points; a
  // target of 0.01 deg over 0.2 s windows needs more points per curve, or runs to the cap of 12
  // and says so.
  TwinRun tight_run;
  VectorSink tight;
  const SweepPlan tight_plan = plan_from(R"({"mode": "adaptive",
    "dimensions": {"speed_rpm": [300, 700], "load_Nm": [2.5]},
    "adaptive": {"angle_u_target_deg": 0.01, "max_evaluations": 12},
    "window_s": 0.2, "thermal": {"enabled": false}})");
  SweepEngine e2(tight_run.bench.devices(), tight_run.sup, tight_plan, {}, tight);
  tight_run.until(e2, 1200);
  ASSERT_EQ(e2.state(), SweepState::completed) << e2.error();
  const auto o2 = sweep_outcome(tight_plan, std::map<std::size_t, PointRecord>(tight.points.begin(), tight.points.end()));
  std::printf("%s", to_text(o2).c_str());
  ASSERT_EQ(o2.curves.size(), 2u);
  EXPECT_GT(o2.points_used, o.points_used);
  for (const auto& c : o2.curves) {
    EXPECT_TRUE(c.finished);
    if (c.result.angle_u_target_met) {
      EXPECT_LT(c.result.evaluations, 12u);
    } else {
      EXPECT_EQ(c.result.evaluations, 12u);
    }
  }
}

}  // namespace
}  // namespace synbench::bench
