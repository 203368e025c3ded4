// The safety supervisor against faults injected through the twin: each class at three operating
// points ends in the ordered stop within a bounded time, latched and recorded, and nothing
// restarts without a reset (issue "Sweep engine, safety supervisor").
#include "bench/safety_supervisor.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "drivers/error.hpp"
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

// The drives as the twin has them, every command logged with the bench time and the plant's
// state when it was sent; the SynRM drive can be made to ignore its disable (a lost write, a
// drive that does not obey).
struct Recorded {
  std::string what;
  double value, t, shaft_rpm, load_Nm;
};
struct RecordingBench {
  explicit RecordingBench(const emulator::TwinConfig& config = {}) : bench(config) {}
  emulator::TwinBench bench;
  double synrm_stop_time_s = 0;  // the SynRM drive's documented stop time, as a profile gives it
  std::vector<Recorded> log;
  double t = 0;
  bool ignore_synrm_disable = false;
  int synrm_disables = 0;
  int lose_synrm_disables = 0;  // the next this many SynRM disables are lost on the link (timeout)
  bool refuse_load_torque = false;
  void note(const char* what, double v) {
    const auto snap = bench.twin().snapshot();
    log.push_back({what, v, t, snap.speed_rpm, snap.load_torque_Nm});
  }
  struct Synrm final : drivers::SynrmDrive {
    RecordingBench& r;
    drivers::SynrmDrive& d;
    Synrm(RecordingBench& rb, drivers::SynrmDrive& dd) : r(rb), d(dd) {}
    std::error_code enable(bool on) override {
      r.note("synrm.enable", on);
      if (!on) ++r.synrm_disables;
      if (!on && r.lose_synrm_disables > 0) {
        --r.lose_synrm_disables;
        return make_error_code(errc::timeout);
      }
      if (!on && r.ignore_synrm_disable) return {};
      return d.enable(on);
    }
    std::error_code set_speed_rpm(double v) override {
      r.note("synrm.speed", v);
      return d.set_speed_rpm(v);
    }
    std::error_code set_angle_deg(double v) override { return d.set_angle_deg(v); }
    std::error_code set_pwm(drivers::Pwm p) override { return d.set_pwm(p); }
    std::error_code set_estimator(drivers::Estimator e) override { return d.set_estimator(e); }
    std::error_code reset_fault() override { return d.reset_fault(); }
    std::error_code read(drivers::SynrmTelemetry& out) override {
      r.note("synrm.read", 0);
      return d.read(out);
    }
    std::error_code read_window(drivers::SynrmWindow& out) override { return d.read_window(out); }
    double stop_time_s() const override { return r.synrm_stop_time_s; }
  } synrm{*this, *bench.devices().synrm};
  struct Load final : drivers::LoadDrive {
    RecordingBench& r;
    drivers::LoadDrive& d;
    Load(RecordingBench& rb, drivers::LoadDrive& dd) : r(rb), d(dd) {}
    std::error_code enable(bool on) override {
      r.note("load.enable", on);
      return d.enable(on);
    }
    std::error_code set_torque_Nm(double v) override {
      r.note("load.torque", v);
      if (r.refuse_load_torque) return make_error_code(errc::exception_reply);
      return d.set_torque_Nm(v);
    }
    std::error_code reset_fault() override { return d.reset_fault(); }
    std::error_code read(drivers::LoadTelemetry& out) override { return d.read(out); }
    std::error_code read_window(drivers::LoadWindow& out) override { return d.read_window(out); }
  } load{*this, *bench.devices().load};
  std::vector<std::pair<std::string, std::string>> events;
  SafetySupervisor sup{devices(), SafetyLimits{},
                       [this](const std::string& k, const std::string& m) { events.emplace_back(k, m); }};

  drivers::BenchDevices devices() {
    auto d = bench.devices();
    d.synrm = &synrm;
    d.load = &load;
    return d;
  }
  void run_until(double end_s) {
    while (t < end_s - 1e-9) {
      t += 0.01;
      bench.clock().wait_until(t);
      sup.tick(t);
    }
  }
  void start(double speed_rpm, double load_Nm) {
    auto d = devices();
    ASSERT_FALSE(d.load->enable(true));
    ASSERT_FALSE(d.synrm->set_angle_deg(56));
    ASSERT_FALSE(d.synrm->set_speed_rpm(speed_rpm));
    ASSERT_FALSE(d.synrm->enable(true));
    run_until(1.5);
    ASSERT_FALSE(d.load->set_torque_Nm(load_Nm));
    run_until(3.0);
    ASSERT_FALSE(sup.tripped());
    log.clear();
  }
  const Recorded* first(const std::string& what, double value) const {
    for (const auto& r : log)
      if (r.what == what && r.value == value) return &r;
    return nullptr;
  }
};

// After a trip the supervisor takes the load torque off first, commands zero speed only once the
// load has let go, and disables both drives only once the shaft has stopped: its phases follow.
TEST(SafetySupervisor, TheOrderedStopTakesTheLoadThenTheSpeedThenDisables) {
  RecordingBench r;
  r.start(700, 2.5);
  // Hotter than the supervisor's 110 degC, cooler than the firmware's own 120: the drives keep
  // control and the stop is the supervisor's.
  r.bench.twin().set_winding_temp_C(112.0);
  std::vector<SafetyPhase> phases;
  for (int i = 0; i < 1500 && r.sup.phase() != SafetyPhase::stopped; ++i) {
    r.run_until(r.t + 0.01);
    if (r.sup.tripped() && (phases.empty() || phases.back() != r.sup.phase())) phases.push_back(r.sup.phase());
  }
  ASSERT_TRUE(r.sup.trip());
  EXPECT_EQ(r.sup.trip()->fault, drivers::Fault::overtemperature);
  const std::vector<SafetyPhase> expected = {SafetyPhase::stopping_load, SafetyPhase::stopping_speed, SafetyPhase::stopped};
  EXPECT_EQ(phases, expected);
  const auto command = std::find_if(r.log.begin(), r.log.end(), [](const Recorded& x) { return x.what != "synrm.read"; });
  ASSERT_NE(command, r.log.end());
  EXPECT_EQ(command->what, "load.torque") << "the first command after the trip";
  EXPECT_EQ(command->value, 0.0);
  const auto* speed0 = r.first("synrm.speed", 0.0);
  const auto* off_s = r.first("synrm.enable", 0.0);
  const auto* off_l = r.first("load.enable", 0.0);
  ASSERT_TRUE(speed0 && off_s && off_l);
  EXPECT_LT(std::fabs(speed0->load_Nm), 0.05) << "zero speed only once the load has let go";
  EXPECT_GT(speed0->shaft_rpm, 500) << "the shaft still turned when the load had gone";
  EXPECT_GT(off_s->t, speed0->t);
  // The drive's speed telemetry is filtered: the plant is a little behind the 20 rpm it saw.
  EXPECT_LT(std::fabs(off_s->shaft_rpm), 40.0) << "disabled once the shaft stopped";
  EXPECT_GE(off_l->t, speed0->t);
  r.run_until(r.t + 0.5);
  EXPECT_FALSE(r.sup.alarm()) << "both drives read back stopped";
  EXPECT_FALSE(r.sup.confirming_stop());
}

// A drive that does not obey its disable is not taken for stopped: the disable it acknowledged is
// repeated at a bounded rate (every kDisableRepeat_s, not every tick: it only loads the line), the
// alarm latches after stop_confirm_s, and no reset hides it while the drive still runs. Once the
// drive obeys, the reset clears the alarm.
TEST(SafetySupervisor, ADriveThatIgnoresItsDisableRaisesTheAlarm) {
  RecordingBench r;
  r.start(500, 1.0);
  r.ignore_synrm_disable = true;
  r.sup.estop(r.t, "test");
  r.run_until(r.t + 0.2);
  EXPECT_FALSE(r.sup.alarm()) << "within stop_confirm_s";
  r.run_until(r.t + 0.2);
  ASSERT_TRUE(r.sup.alarm());
  EXPECT_NE(r.sup.alarm()->detail.find("SynRM drive still reports running"), std::string::npos) << r.sup.alarm()->detail;
  EXPECT_EQ(r.sup.alarm()->detail.find("load drive"), std::string::npos) << "the load obeyed";
  EXPECT_GE(r.synrm_disables, 4) << "the disable is repeated";
  EXPECT_LE(r.synrm_disables, 6) << "at most every " << kDisableRepeat_s << " s in 0.4 s, not every tick";
  EXPECT_EQ(r.sup.disable_report()->synrm.state, DisableState::repeating);
  EXPECT_EQ(r.sup.disable_report()->synrm.error, "still reports running");
  bool alarm_event = false;
  for (const auto& [k, m] : r.events) alarm_event = alarm_event || (k == "alarm" && m.find("ALARM") == 0);
  EXPECT_TRUE(alarm_event);
  EXPECT_EQ(r.sup.reset(), make_error_code(errc::busy));
  EXPECT_TRUE(r.sup.tripped());
  r.ignore_synrm_disable = false;
  r.run_until(r.t + kDisableRepeat_s + 0.03);  // the next repeat goes through
  EXPECT_FALSE(r.sup.confirming_stop());
  EXPECT_FALSE(r.sup.reset());
  EXPECT_FALSE(r.sup.alarm());
  EXPECT_FALSE(r.sup.tripped());
}

// A drive that ramps down on its disable (an SS1-style stop: the twin's firmware.disable_action
// "ramp", reading stopping) after an E-stop at 1000 rpm. With its documented stop time (what a
// profile's stop_time_ms gives) the supervisor leaves it to its ramp: one disable request, state
// stopping, no alarm, confirmed once it reads disabled about 1 s later (1000 rpm at 1000 rpm/s).
// Without it, the alarm latches after stop_confirm_s and the repeats come at the bounded rate.
TEST(SafetySupervisor, ADriveRampingDownWithinItsStopTimeIsLeftToItsRamp) {
  emulator::TwinConfig c;
  c.firmware.disable_action = emulator::DisableAction::ramp;
  ASSERT_DOUBLE_EQ(c.firmware.stop_time_s(), 1.5) << "1500 rpm at 1000 rpm/s";
  for (const bool documented : {true, false}) {
    SCOPED_TRACE(documented ? "stop time documented" : "no stop time");
    RecordingBench r(c);
    r.synrm_stop_time_s = documented ? c.firmware.stop_time_s() : 0.0;
    r.start(1000, 1.0);
    const double t0 = r.t;
    r.sup.estop(t0, "test");
    r.run_until(t0 + 0.2);
    ASSERT_TRUE(r.sup.disable_report());
    EXPECT_EQ(r.sup.disable_report()->synrm.state, DisableState::stopping) << r.sup.disable_report()->synrm.error;
    EXPECT_EQ(r.bench.twin().synrm_drive().state(), drivers::DriveState::stopping);
    r.run_until(t0 + 0.5);
    // The far side: the shaft follows the drive's ramp, not a coast (the load let go at once).
    EXPECT_NEAR(r.bench.twin().snapshot().speed_rpm, 500.0, 120.0);
    r.run_until(t0 + 2.5);
    const DisableReport& d = *r.sup.disable_report();
    EXPECT_EQ(d.synrm.state, DisableState::confirmed);
    ASSERT_TRUE(d.synrm.confirmed_s);
    EXPECT_NEAR(*d.synrm.confirmed_s - t0, 1.0, 0.25) << "read back disabled at the end of the ramp";
    EXPECT_EQ(r.bench.twin().synrm_drive().state(), drivers::DriveState::disabled) << "a disable's ramp latches no fault";
    EXPECT_FALSE(r.sup.confirming_stop());
    if (documented) {
      EXPECT_FALSE(r.sup.alarm()) << r.sup.alarm()->detail;
      EXPECT_EQ(r.synrm_disables, 1) << "a drive ramping within its stop time is not sent its disable again";
      EXPECT_TRUE(d.synrm.setpoint_zeroed) << "the zero speed the drive ramps to is accepted while stopping";
    } else {
      ASSERT_TRUE(r.sup.alarm());
      EXPECT_NEAR(r.sup.alarm()->at_s - t0, 0.3, 0.02);
      EXPECT_NE(r.sup.alarm()->detail.find("the SynRM drive still reports stopping"), std::string::npos) << r.sup.alarm()->detail;
      EXPECT_GE(r.synrm_disables, 5);
      EXPECT_LE(r.synrm_disables, 10) << "repeated at most every " << kDisableRepeat_s << " s over the 0.7 s past the deadline";
      EXPECT_FALSE(r.sup.reset()) << "both read back stopped: the reset clears the alarm";
    }
  }
}

// An E-stop whose SynRM disable is lost on the link: the load's is sent all the same, each once,
// and the report says so per drive (what the E-stop answers); every following tick repeats the
// lost one before reading the drives (a starved line's reads must not hold it back) until it
// goes through and the drive reads back disabled. Nothing is reported disabled that was not.
TEST(SafetySupervisor, AnEStopReportsEachDriveAndRepeatsALostDisableBeforeTheReads) {
  RecordingBench r;
  r.start(600, 1.5);
  r.lose_synrm_disables = 4;
  r.sup.estop(r.t, "test");
  ASSERT_TRUE(r.sup.disable_report());
  const DisableReport first = *r.sup.disable_report();
  EXPECT_FALSE(first.synrm.first_acknowledged);
  EXPECT_EQ(first.synrm.state, DisableState::repeating);
  EXPECT_EQ(first.synrm.attempts, 1);
  EXPECT_NE(first.synrm.error.find("disable not acknowledged"), std::string::npos) << first.synrm.error;
  EXPECT_TRUE(first.load.first_acknowledged);
  EXPECT_EQ(first.load.state, DisableState::acknowledged);
  EXPECT_EQ(first.load.attempts, 1);
  EXPECT_FALSE(first.confirmed());
  ASSERT_GE(r.log.size(), 2u);
  EXPECT_EQ(r.log[0].what, "synrm.enable");
  EXPECT_EQ(r.log[1].what, "load.enable") << "the load's disable right after the SynRM's single attempt";
  EXPECT_EQ(r.synrm_disables, 1) << "one request per drive before the caller is answered";
  for (int tick = 0; tick < 3; ++tick) {
    const std::size_t from = r.log.size();
    r.run_until(r.t + 0.01);
    ASSERT_GT(r.log.size(), from + 1);
    EXPECT_EQ(r.log[from].what, "synrm.enable") << "tick " << tick << ": the repeat goes before the reads";
    EXPECT_EQ(r.log[from].value, 0.0);
    EXPECT_EQ(r.log[from + 1].what, "synrm.read");
    EXPECT_EQ(r.sup.disable_report()->synrm.state, DisableState::repeating);
    EXPECT_GT(r.bench.twin().snapshot().speed_rpm, 300) << "the SynRM was never disabled: it runs on";
  }
  r.run_until(r.t + 0.02);  // the fifth request goes through, the next read confirms it
  const DisableReport& now = *r.sup.disable_report();
  EXPECT_EQ(now.synrm.state, DisableState::confirmed);
  EXPECT_EQ(now.synrm.attempts, 5);
  EXPECT_FALSE(now.synrm.first_acknowledged) << "the first attempt's verdict is kept";
  EXPECT_TRUE(now.synrm.error.empty()) << now.synrm.error;
  EXPECT_EQ(now.load.state, DisableState::confirmed);
  EXPECT_TRUE(now.confirmed());
  EXPECT_FALSE(r.sup.confirming_stop());
  EXPECT_FALSE(r.sup.alarm());
  bool said_failed = false, said_confirmed = false;
  for (const auto& [k, m] : r.events) {
    said_failed = said_failed || (k == "fault" && m.find("disabling the SynRM drive failed") == 0);
    said_confirmed = said_confirmed || (k == "state" && m.find("the SynRM drive reads back disabled after 5") == 0);
  }
  EXPECT_TRUE(said_failed);
  EXPECT_TRUE(said_confirmed);
  EXPECT_FALSE(r.sup.reset());
  EXPECT_FALSE(r.sup.disable_report()) << "a reset clears it";
}

// After a stop's disable (an E-stop here, a trip's ordered stop below) the drives' setpoints are
// written to zero: never before the disable, and a refused setpoint write neither delays nor
// prevents it.
TEST(SafetySupervisor, AfterTheDisableTheSetpointsGoToZero) {
  RecordingBench r;
  r.start(800, 1.5);
  r.refuse_load_torque = true;
  r.sup.estop(r.t, "test");
  r.run_until(r.t + 0.05);
  const auto* off_s = r.first("synrm.enable", 0.0);
  const auto* off_l = r.first("load.enable", 0.0);
  const auto* speed0 = r.first("synrm.speed", 0.0);
  const auto* torque0 = r.first("load.torque", 0.0);
  ASSERT_TRUE(off_s && off_l && speed0 && torque0);
  EXPECT_LT(off_s, speed0) << "the disables first";
  EXPECT_LT(off_l, speed0);
  EXPECT_LT(off_l, torque0);
  const DisableReport& rep = *r.sup.disable_report();
  EXPECT_TRUE(rep.confirmed()) << "the refused torque write did not hold the disable back";
  EXPECT_TRUE(rep.synrm.setpoint_zeroed);
  EXPECT_FALSE(rep.load.setpoint_zeroed) << "refused: not claimed";
  EXPECT_EQ(r.bench.twin().synrm_drive().state(), drivers::DriveState::disabled);
  bool said = false;
  for (const auto& [k, m] : r.events) said = said || (k == "fault" && m.find("the setpoints could not be written to zero") == 0);
  EXPECT_TRUE(said);

  // A trip's ordered stop, this time with nothing refused: both setpoints read zero after it.
  RecordingBench t;
  t.start(700, 2.5);
  t.bench.twin().set_winding_temp_C(112.0);
  for (int i = 0; i < 1500 && t.sup.phase() != SafetyPhase::stopped; ++i) t.run_until(t.t + 0.01);
  t.run_until(t.t + 0.1);
  ASSERT_TRUE(t.sup.disable_report());
  EXPECT_TRUE(t.sup.disable_report()->confirmed());
  EXPECT_TRUE(t.sup.disable_report()->synrm.setpoint_zeroed);
  EXPECT_TRUE(t.sup.disable_report()->load.setpoint_zeroed);
  const Recorded& last_torque = *std::find_if(t.log.rbegin(), t.log.rend(), [](const Recorded& x) { return x.what == "load.torque"; });
  const Recorded& last_speed = *std::find_if(t.log.rbegin(), t.log.rend(), [](const Recorded& x) { return x.what == "synrm.speed"; });
  EXPECT_EQ(last_torque.value, 0.0);
  EXPECT_EQ(last_speed.value, 0.0);
}

// A plan tightens the bench's limits, each bound on its own; it never loosens them.
TEST(SafetySupervisor, StricterTakesEachBoundOnItsOwn) {
  SafetyLimits bench_l, plan_l;
  bench_l.max_current_A = 4.0;
  plan_l.max_current_A = 0.5;
  plan_l.max_speed_rpm = 2000;
  plan_l.min_udc_V = 350;
  const SafetyLimits s = stricter(bench_l, plan_l);
  EXPECT_EQ(s.max_current_A, 0.5);
  EXPECT_EQ(s.max_speed_rpm, bench_l.max_speed_rpm);
  EXPECT_EQ(s.min_udc_V, 350);
  EXPECT_EQ(s.max_udc_V, bench_l.max_udc_V);
}

}  // namespace
}  // namespace synbench::bench
