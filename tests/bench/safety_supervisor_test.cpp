// The safety supervisor against faults injected through the twin: each class at three operating
// points ends in the ordered stop within a bounded time, latched and recorded, and nothing
// restarts without a reset (issue "Sweep engine, safety supervisor").
#include "bench/safety_supervisor.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "emulator/twin_bench.hpp"

namespace synbench::bench {
namespace {

struct Op {
  double speed_rpm, load_Nm, angle_deg;
};
const Op kOps[] = {{300, 1.0, 56}, {700, 2.5, 56}, {900, 3.5, 58}};

struct Harness {
  emulator::TwinBench bench{emulator::TwinConfig{}};
  std::vector<std::pair<std::string, std::string>> events;
  SafetySupervisor sup{bench.devices(), SafetyLimits{},
                       [this](const std::string& k, const std::string& m) { events.emplace_back(k, m); }};
  double t = 0;

  void run_until(double end_s, const std::function<bool()>& done = {}) {
    while (t < end_s - 1e-9) {
      t += 0.01;
      bench.clock().wait_until(t);
      sup.tick(t);
      if (done && done()) return;
    }
  }
  void start(const Op& op) {
    auto d = bench.devices();
    ASSERT_FALSE(d.load->enable(true));
    ASSERT_FALSE(d.synrm->set_angle_deg(op.angle_deg));
    ASSERT_FALSE(d.synrm->set_speed_rpm(op.speed_rpm));
    ASSERT_FALSE(d.synrm->enable(true));
    run_until(1.5);
    ASSERT_FALSE(d.load->set_torque_Nm(op.load_Nm));
    run_until(3.0);
    ASSERT_FALSE(sup.tripped()) << (sup.trip() ? sup.trip()->detail : "");
    ASSERT_NEAR(bench.twin().snapshot().speed_rpm, op.speed_rpm, 0.05 * op.speed_rpm);
  }
  bool drives_off() {
    return bench.twin().synrm_drive().state() != drivers::DriveState::running &&
           bench.twin().synrm_drive().state() != drivers::DriveState::stopping;
  }
};

using Inject = std::function<void(Harness&)>;

// Runs one class at one point; returns the bench time from injection to both drives off and the
// shaft below 20 rpm.
double check_class(const Op& op, const Inject& inject, drivers::Fault expected,
                   bool link_cut = false) {
  Harness h;
  h.start(op);
  const double t_inject = h.t;
  inject(h);
  double t_stopped = -1;
  h.run_until(t_inject + 20.0, [&] {
    if (t_stopped < 0 && h.drives_off() && std::fabs(h.bench.twin().snapshot().speed_rpm) < 20.0 &&
        std::fabs(h.bench.twin().snapshot().load_torque_Nm) < 0.05)
      t_stopped = h.t;
    return t_stopped >= 0 && h.t > t_stopped + 1.0;
  });
  const std::string at = std::string(drivers::fault_name(expected)) + " at " + std::to_string(op.speed_rpm) + " rpm";
  EXPECT_GE(t_stopped, 0) << at << ": never stopped";
  EXPECT_TRUE(h.sup.tripped()) << at;
  if (h.sup.trip()) {
    EXPECT_EQ(h.sup.trip()->fault, expected) << at << ": " << h.sup.trip()->detail;
  }
  EXPECT_FALSE(h.events.empty()) << at << ": not recorded";
  if (!h.events.empty()) {
    EXPECT_EQ(h.events.front().first, "fault") << at;
  }
  if (link_cut) {
    h.bench.set_link_down(false);
    h.run_until(h.t + 1.0);
  }
  // Latched: still stopped a while later, the drives refuse to run, nothing restarts by itself.
  h.run_until(h.t + 2.0);
  EXPECT_LT(std::fabs(h.bench.twin().snapshot().speed_rpm), 20.0) << at;
  EXPECT_TRUE(h.sup.tripped()) << at;
  EXPECT_FALSE(h.sup.may_command()) << at;
  // An explicit reset clears the latch but starts nothing.
  h.bench.twin().faults() = emulator::PlantFaults{};
  if (expected == drivers::Fault::overtemperature) h.bench.twin().set_winding_temp_C(50);
  h.run_until(h.t + 1.0);
  EXPECT_FALSE(h.sup.reset()) << at;
  h.run_until(h.t + 1.0);
  EXPECT_FALSE(h.sup.tripped()) << at;
  EXPECT_TRUE(h.drives_off()) << at;
  EXPECT_LT(std::fabs(h.bench.twin().snapshot().speed_rpm), 20.0) << at;
  return t_stopped - t_inject;
}

TEST(SafetySupervisor, EveryFaultClassEndsInALatchedOrderedStop) {
  struct Case {
    const char* name;
    drivers::Fault expected;
    Inject inject;
    bool link_cut = false;
  };
  const std::vector<Case> cases = {
      {"over-speed (load runaway)", drivers::Fault::overspeed,
       [](Harness& h) { h.bench.twin().load_drive().inject_runaway(9.0); }},
      {"over-current (sensor)", drivers::Fault::overcurrent,
       [](Harness& h) { h.bench.twin().faults().phase_a_sensor_offset_A = 7.0; }},
      {"over-voltage (mains surge)", drivers::Fault::overvoltage,
       [](Harness& h) { h.bench.twin().faults().source_offset_V = 45.0; }},
      {"over-temperature", drivers::Fault::overtemperature,
       [](Harness& h) { h.bench.twin().set_winding_temp_C(115.0); }},
      {"link loss", drivers::Fault::link_loss, [](Harness& h) { h.bench.set_link_down(true); }, true},
      {"E-stop", drivers::Fault::estop, [](Harness& h) { h.sup.estop(h.t); }},
  };
  std::map<std::string, double> worst;
  for (const auto& c : cases)
    for (const auto& op : kOps) {
      const double dt = check_class(op, c.inject, c.expected, c.link_cut);
      worst[c.name] = std::max(worst[c.name], dt);
      if (std::getenv("SYNBENCH_VERBOSE")) std::printf("%s @ %.0f rpm: %.2f s\n", c.name, op.speed_rpm, dt);
    }
  for (const auto& [name, dt] : worst) {
    std::printf("  %-28s stopped within %.2f s\n", name.c_str(), dt);
    EXPECT_LT(dt, 10.0) << name;  // the worst case is a coast-down from the firmware's 1800 rpm trip
  }
}

}  // namespace
}  // namespace synbench::bench
