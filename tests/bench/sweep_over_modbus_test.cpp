// A short sweep on the emulated bench over real Modbus TCP (libmodbus on loopback to the twin's
// in-process server), under the safety supervisor, with a lossy link: about 2 % of the
// transactions delayed past the timeout, dropped, answered with an exception or corrupted, as
// a real RS-485 line is. Every point must be measured; and when the link is really cut, the
// supervisor must trip link_loss within its deadline.
#include <gtest/gtest.h>
#include "drivers/json.hpp"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "bench/safety_supervisor.hpp"
#include "bench/sweep_engine.hpp"
#include "bench/sweep_plan.hpp"
#include "drivers/profile_devices/profile_bench.hpp"
#include "drivers/real_time_clock.hpp"
#include "tests/drivers/bus/modbus_link_fixture.hpp"

namespace synbench::bench {
namespace {

// Twin seconds per wall second: fast enough for a short test, slow enough that the link's
// wall-time timeouts (50 ms = 0.1 s of bench time) fit the supervisor's 0.5 s deadline.
constexpr double kTimeScale = 2.0;

struct VectorSink : SweepSink {
  std::vector<PointRecord> points;
  std::vector<std::string> events;
  std::error_code store_point(std::size_t, const PointRecord& r) override {
    points.push_back(r);
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

// Four chained points of one curve: one spin-up, three retargets, one ordered stop at the end.
const char* kShortSweep = R"({
  "name": "lossy link",
  "dimensions": {"speed_rpm": [600], "load_Nm": [1.5], "angle_deg": [48, 54, 60, 66]},
  "window_s": 0.5,
  "thermal": {"enabled": false}
})";

drivers::ModbusLinkOptions fast_link() {
  auto o = testing::link_options(0.05);
  o.reconnect_max_s = 0.2;
  return o;
}

struct LossyBench {
  explicit LossyBench(const emulator::FaultPlan& plan)
      : emu(plan, kTimeScale),
        bus({"127.0.0.1", emu.start_tcp()}, fast_link()),
        clock(kTimeScale),
        bench(bus, emu.profiles[0], bus, emu.profiles[1], bus, emu.profiles[2], clock, options()),
        sup(bench.devices(), SafetyLimits{}, [this](const std::string& k, const std::string& m) {
          events.push_back(k + ": " + m);
        }) {}

  static drivers::ProfileBenchOptions options() {
    drivers::ProfileBenchOptions o;
    o.window_margin_s = 5.0;
    return o;
  }

  // Ticks the supervisor, then `after`, every 10 ms of bench time, as the daemon does.
  template <class F>
  void run(double max_s, F&& after) {
    const double t0 = clock.now_s();
    double t = t0;
    while (clock.now_s() - t0 < max_s) {
      t = std::max(t + 0.01, clock.now_s());
      bench.clock().wait_until(t);
      const double now = clock.now_s();
      sup.tick(now);
      if (after(now)) return;
    }
  }

  testing::Emulator emu;
  drivers::ModbusTcpBus bus;
  drivers::RealTimeClock clock;
  drivers::ProfileBench bench;
  std::vector<std::string> events;
  SafetySupervisor sup;
};

void print_counts(const char* what, const LossyBench& b) {
  const auto f = b.emu.faults.counts();
  const auto s = b.bus.stats();
  std::printf("%s: injected %llu delayed, %llu dropped, %llu exceptions, %llu corrupted of %llu; bus %llu "
              "transactions, %llu timeouts, %llu exceptions, %llu protocol errors, %llu link errors\n",
              what, static_cast<unsigned long long>(f.delayed), static_cast<unsigned long long>(f.dropped),
              static_cast<unsigned long long>(f.exceptions), static_cast<unsigned long long>(f.corrupted),
              static_cast<unsigned long long>(f.requests), static_cast<unsigned long long>(s.transactions),
              static_cast<unsigned long long>(s.timeouts), static_cast<unsigned long long>(s.exceptions),
              static_cast<unsigned long long>(s.protocol_errors), static_cast<unsigned long long>(s.link_errors));
}

void sweep_on_lossy_link(const emulator::FaultPlan& plan, const char* what) {
  LossyBench b(plan);
  VectorSink sink;
  SweepEngine e(b.bench.devices(), b.sup, plan_from(kShortSweep), {}, sink);
  b.run(120.0, [&](double now) {
    e.tick(now);
    return e.finished();
  });
  print_counts(what, b);
  std::printf("%s: %zu of 4 points, sweep %s %s\n", what, sink.points.size(),
              std::string(name(e.state())).c_str(), e.error().c_str());
  for (const auto& ev : b.events) std::printf("  supervisor %s\n", ev.c_str());
  EXPECT_EQ(e.state(), SweepState::completed) << e.error();
  ASSERT_EQ(sink.points.size(), 4u);
  for (const auto& p : sink.points) {
    EXPECT_FALSE(p.fault) << *p.fault;
    // Measured, not made up: the window saw the commanded operating point.
    EXPECT_NEAR(p.speed_meas_rpm, 600, 10);
    EXPECT_GT(p.im_A, 0.5);
    EXPECT_GT(p.pdcm_W, 0);
  }
  EXPECT_FALSE(b.sup.tripped()) << b.sup.trip()->detail;
}

TEST(SweepOverModbus, CompletesEveryPointWithTwoPercentOfTransactionsFaulted) {
  emulator::FaultPlan plan;
  plan.delay_pct = 0.5;
  plan.drop_pct = 0.5;
  plan.exception_pct = 0.5;
  plan.corrupt_pct = 0.5;
  plan.delay_s = 0.2;  // past the 50 ms response timeout
  plan.seed = 7;
  sweep_on_lossy_link(plan, "2 % mixed");
}

TEST(SweepOverModbus, CompletesEveryPointWithTwoPercentExceptions) {
  emulator::FaultPlan plan;
  plan.exception_pct = 2;
  plan.seed = 11;
  sweep_on_lossy_link(plan, "2 % exceptions");
}

TEST(SweepOverModbus, CompletesEveryPointWithTwoPercentDropped) {
  emulator::FaultPlan plan;
  plan.drop_pct = 2;
  plan.seed = 13;
  sweep_on_lossy_link(plan, "2 % dropped");
}

// Drives running at a point, with the same lossy link; returns once the sweep's first point is
// stored (the bench is settled and the supervisor has seen seconds of good telemetry).
void run_first_point(LossyBench& b, SweepEngine& e, VectorSink& sink) {
  b.run(60.0, [&](double now) {
    e.tick(now);
    return !sink.points.empty() || e.finished();
  });
  ASSERT_EQ(sink.points.size(), 1u) << e.error();
  ASSERT_FALSE(b.sup.tripped()) << b.sup.trip()->detail;
}

TEST(SweepOverModbus, ACutLinkTripsLinkLossWithinTheDeadline) {
  emulator::FaultPlan plan;
  plan.drop_pct = 1;
  plan.exception_pct = 1;
  plan.seed = 17;
  LossyBench b(plan);
  VectorSink sink;
  SweepEngine e(b.bench.devices(), b.sup, plan_from(kShortSweep), {}, sink);
  run_first_point(b, e, sink);

  const double cut_at = b.clock.now_s();
  b.emu.faults.cut_link(5.0 / kTimeScale);  // 5 s of bench time
  b.run(4.0, [&](double now) {
    e.tick(now);
    return b.sup.tripped();
  });
  ASSERT_TRUE(b.sup.tripped());
  const auto& trip = *b.sup.trip();
  const double after_s = trip.at_s - cut_at;
  std::printf("link cut: %s after %.3f s of bench time (%s)\n", std::string(drivers::fault_name(trip.fault)).c_str(),
              after_s, trip.detail.c_str());
  EXPECT_EQ(trip.fault, drivers::Fault::link_loss) << trip.detail;
  // The deadline runs from the last good read, which came before the cut (by the sweep's own
  // work in that tick): at most the deadline after the cut, plus one tick, one retry budget and
  // one response timeout; and the supervisor waited out the whole deadline.
  const SafetyLimits lim;
  EXPECT_GT(after_s, 0.0);
  EXPECT_LE(after_s, lim.link_timeout_s + 0.01 + 0.25 + 0.05 * kTimeScale);
  EXPECT_NE(trip.detail.find("no telemetry for"), std::string::npos) << trip.detail;
  EXPECT_EQ(e.state(), SweepState::faulted);
}

TEST(SweepOverModbus, AStuckCurrentTripsImplausibleTelemetry) {
  emulator::FaultPlan plan;  // a clean link: the finding must be the stuck value, nothing else
  LossyBench b(plan);
  VectorSink sink;
  SweepEngine e(b.bench.devices(), b.sup, plan_from(kShortSweep), {}, sink);
  run_first_point(b, e, sink);

  // The drive's I_m keeps the value of its next read (emulate's --fault-stuck 1:im_A).
  ASSERT_FALSE(b.emu.service.locked([](auto&, auto&, emulator::RegisterServer& r) { return r.stick(1, "im_A"); }));
  const double stuck_at = b.clock.now_s();
  b.run(10.0, [&](double now) {
    e.tick(now);
    return b.sup.tripped();
  });
  ASSERT_TRUE(b.sup.tripped());
  const auto& trip = *b.sup.trip();
  std::printf("stuck im_A: %s after %.3f s (%s)\n", std::string(drivers::fault_name(trip.fault)).c_str(),
              trip.at_s - stuck_at, trip.detail.c_str());
  EXPECT_EQ(trip.fault, drivers::Fault::implausible_telemetry) << trip.detail;
  EXPECT_NE(trip.detail.find("im_A"), std::string::npos) << trip.detail;
  EXPECT_NE(trip.detail.find("frozen"), std::string::npos) << trip.detail;
  // frozen_s (1 s) after it stuck, plus ticks.
  EXPECT_GE(trip.at_s - stuck_at, 0.99);
  EXPECT_LE(trip.at_s - stuck_at, 1.5);
}

}  // namespace
}  // namespace synbench::bench
