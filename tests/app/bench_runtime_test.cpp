// The bench runtime on the twin, in real time: commands are acted on by the bench thread in
// order, an E-stop goes ahead of every command queued before it, every command is answered (also
// at the shutdown), and a plan's stricter limits bind a sweep the daemon runs.
#include "app/bench_runtime.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <chrono>
#include <filesystem>
#include <future>
#include <thread>
#include <vector>

#include "bench/sweep_plan.hpp"
#include "emulator/twin_bench.hpp"

namespace synbench::app {
namespace {

class TwinBackend final : public BenchBackend {
 public:
  TwinBackend() : twin_(emulator::TwinConfig{}) {}
  drivers::BenchDevices devices() override { return twin_.devices(); }
  drivers::Clock& clock() override { return twin_.clock(); }
  synbench::Json describe() const override { return synbench::Json::array(); }
  const BenchDescription& description() const override { return description_; }
  // Set from the test thread, acted on by the bench thread (the one owner of the twin).
  std::atomic<double> heat_winding_to_C{0.0};
  void tick(double) override {
    if (const double t = heat_winding_to_C.exchange(0.0); t > 0.0) twin_.twin().set_winding_temp_C(t);
  }

 private:
  emulator::TwinBench twin_;
  BenchDescription description_;
};

// Collects outcomes in the order the bench thread gives them.
struct Answers {
  std::mutex m;
  std::vector<std::pair<std::string, Outcome>> got;
  BenchRuntime::Done done(std::string what) {
    return [this, what](Outcome o) {
      std::lock_guard lock(m);
      got.emplace_back(what, std::move(o));
    };
  }
  std::size_t size() {
    std::lock_guard lock(m);
    return got.size();
  }
};

bool wait_for(const std::function<bool()>& cond, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (cond()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return cond();
}

TEST(BenchRuntime, AnEstopGoesAheadOfEveryCommandQueuedBeforeIt) {
  BenchRuntime rt(std::make_unique<TwinBackend>());
  Answers a;
  // Queued before the bench thread runs, so the order the thread acts in is the test's to see.
  for (int i = 0; i < 5; ++i) rt.set_setpoints({100.0 + i, std::nullopt, std::nullopt}, a.done("setpoints"));
  rt.estop("test", a.done("estop"));
  rt.start();
  ASSERT_TRUE(wait_for([&] { return a.size() == 6; }, 5.0));
  EXPECT_EQ(a.got.front().first, "estop");
  EXPECT_FALSE(a.got.front().second.refusal);
  ASSERT_TRUE(a.got.front().second.snapshot);
  EXPECT_EQ(a.got.front().second.snapshot->status.phase, bench::SafetyPhase::estopped);
  EXPECT_FALSE(a.got.front().second.snapshot->status.heartbeats);
  for (std::size_t i = 1; i < a.got.size(); ++i) {
    ASSERT_TRUE(a.got[i].second.refusal) << i;
    EXPECT_EQ(a.got[i].second.refusal->code, Refused::tripped) << "acted on after the E-stop";
  }
  // The setpoints never reached the bench.
  EXPECT_EQ(rt.snapshot()->status.setpoints.speed_rpm, 0.0);
  Answers r;
  rt.reset(r.done("reset"));
  ASSERT_TRUE(wait_for([&] { return r.size() == 1; }, 5.0));
  EXPECT_FALSE(r.got[0].second.refusal);
  EXPECT_TRUE(r.got[0].second.snapshot->status.heartbeats);
  EXPECT_FALSE(r.got[0].second.snapshot->status.trip);
}

TEST(BenchRuntime, ACommandIsAnsweredAfterTheBenchActedAndEveryOneAtTheShutdown) {
  BenchRuntime rt(std::make_unique<TwinBackend>());
  rt.start();
  Answers a;
  rt.set_setpoints({300.0, 0.0, 50.0}, a.done("setpoints"));
  rt.enable(true, a.done("enable"));
  ASSERT_TRUE(wait_for([&] { return a.size() == 2; }, 5.0));
  ASSERT_FALSE(a.got[1].second.refusal);
  // The snapshot in the answer is taken after the drives were read back.
  ASSERT_TRUE(a.got[1].second.snapshot->status.synrm);
  EXPECT_TRUE(drivers::running(a.got[1].second.snapshot->status.synrm->state));
  rt.shutdown();
  Answers late;
  rt.enable(true, late.done("enable"));
  rt.estop("late", late.done("estop"));
  ASSERT_EQ(late.size(), 2u);
  EXPECT_EQ(late.got[0].second.refusal->code, Refused::shutting_down);
  EXPECT_EQ(late.got[1].second.refusal->code, Refused::shutting_down);
  const auto& s = rt.snapshot()->status;
  ASSERT_TRUE(s.synrm);
  EXPECT_FALSE(drivers::running(s.synrm->state)) << "the shutdown ends with the drives read back disabled";
  EXPECT_FALSE(s.alarm);
}

// An E-stop zeroes the held speed and load setpoints (the angle stays): its own answer says so,
// the drives' setpoints were written to 0 behind the disables, and Enable after the reset starts
// at 0 rpm instead of going straight back to where the bench was stopped. A latched trip (here the
// winding's temperature) does the same.
TEST(BenchRuntime, AnEstopOrATripZeroesTheHeldSetpoints) {
  auto owned = std::make_unique<TwinBackend>();
  TwinBackend* backend = owned.get();
  BenchRuntime rt(std::move(owned));
  rt.start();
  const auto run = [&](const std::function<void(BenchRuntime::Done)>& cmd) {
    std::promise<Outcome> p;
    cmd([&p](Outcome o) { p.set_value(std::move(o)); });
    auto f = p.get_future();
    EXPECT_EQ(f.wait_for(std::chrono::seconds(5)), std::future_status::ready);
    return f.get();
  };
  ASSERT_FALSE(run([&](auto d) { rt.set_setpoints({900.0, 2.0, 55.0}, d); }).refusal);
  ASSERT_FALSE(run([&](auto d) { rt.enable(true, d); }).refusal);
  ASSERT_TRUE(wait_for([&] { return rt.snapshot()->status.synrm && rt.snapshot()->status.synrm->speed_rpm > 100.0; }, 5.0));

  const Outcome e = run([&](auto d) { rt.estop("E-stop by test (viewer)", d); });
  ASSERT_FALSE(e.refusal);
  const auto& st = e.snapshot->status;
  EXPECT_EQ(st.setpoints.speed_rpm, 0.0) << "the E-stop's own answer shows the zeroed setpoints";
  EXPECT_EQ(st.setpoints.load_Nm, 0.0);
  EXPECT_EQ(st.setpoints.angle_deg, 55.0) << "the angle is kept";
  ASSERT_TRUE(st.disable);
  EXPECT_TRUE(st.disable->synrm.setpoint_zeroed) << "written behind the acknowledged disable, before the answer";
  EXPECT_TRUE(st.disable->load.setpoint_zeroed);
  ASSERT_TRUE(st.trip);
  EXPECT_EQ(st.trip->detail, "E-stop by test (viewer)");
  bool told = false;
  for (const auto& ev : st.events) told = told || (ev.kind == "setpoints" && ev.message.find("zeroed") != std::string::npos);
  EXPECT_TRUE(told) << "an event says the setpoints were zeroed";

  ASSERT_TRUE(wait_for([&] { return !rt.snapshot()->status.synrm || !drivers::running(rt.snapshot()->status.synrm->state); }, 5.0));
  ASSERT_TRUE(wait_for([&] { return rt.snapshot()->status.synrm && std::abs(rt.snapshot()->status.synrm->speed_rpm) < 5.0; }, 10.0));
  ASSERT_FALSE(run([&](auto d) { rt.reset(d); }).refusal);
  const Outcome en = run([&](auto d) { rt.enable(true, d); });
  ASSERT_FALSE(en.refusal);
  EXPECT_EQ(en.snapshot->status.setpoints.speed_rpm, 0.0);
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  ASSERT_TRUE(rt.snapshot()->status.synrm);
  EXPECT_LT(std::abs(rt.snapshot()->status.synrm->speed_rpm), 20.0) << "Enable did not go back to 900 rpm";

  // A trip that is not an E-stop: the winding over its limit while running.
  ASSERT_FALSE(run([&](auto d) { rt.set_setpoints({600.0, 1.0, std::nullopt}, d); }).refusal);
  backend->heat_winding_to_C = 130.0;
  ASSERT_TRUE(wait_for([&] { return rt.snapshot()->status.trip.has_value(); }, 5.0));
  ASSERT_TRUE(wait_for([&] { return rt.snapshot()->status.setpoints.speed_rpm == 0.0; }, 5.0));
  EXPECT_EQ(rt.snapshot()->status.setpoints.load_Nm, 0.0);
  rt.shutdown();
}

// The twin's drives, whose reads take `slow_read_s` of wall time each once a disable was sent:
// a starved line, where every read of the tick times out.
class SlowReadsAfterDisable final : public BenchBackend {
 public:
  SlowReadsAfterDisable() : twin_(emulator::TwinConfig{}), synrm_(*this, *twin_.devices().synrm), load_(*this, *twin_.devices().load) {}
  drivers::BenchDevices devices() override {
    auto d = twin_.devices();
    d.synrm = &synrm_;
    d.load = &load_;
    return d;
  }
  drivers::Clock& clock() override { return twin_.clock(); }
  synbench::Json describe() const override { return synbench::Json::array(); }
  const BenchDescription& description() const override { return description_; }
  std::atomic<double> slow_read_s{0.3};
  std::atomic<bool> disabled{false};

 private:
  void maybe_slow() {
    if (disabled) std::this_thread::sleep_for(std::chrono::duration<double>(slow_read_s.load()));
  }
  struct Synrm final : drivers::SynrmDrive {
    SlowReadsAfterDisable& b;
    drivers::SynrmDrive& d;
    Synrm(SlowReadsAfterDisable& bb, drivers::SynrmDrive& dd) : b(bb), d(dd) {}
    std::error_code enable(bool on) override {
      if (!on) b.disabled = true;
      return d.enable(on);
    }
    std::error_code set_speed_rpm(double v) override { return d.set_speed_rpm(v); }
    std::error_code set_angle_deg(double v) override { return d.set_angle_deg(v); }
    std::error_code set_pwm(drivers::Pwm p) override { return d.set_pwm(p); }
    std::error_code set_estimator(drivers::Estimator e) override { return d.set_estimator(e); }
    std::error_code reset_fault() override { return d.reset_fault(); }
    std::error_code read(drivers::SynrmTelemetry& out) override {
      b.maybe_slow();
      return d.read(out);
    }
    std::error_code read_window(drivers::SynrmWindow& out) override { return d.read_window(out); }
  };
  struct Load final : drivers::LoadDrive {
    SlowReadsAfterDisable& b;
    drivers::LoadDrive& d;
    Load(SlowReadsAfterDisable& bb, drivers::LoadDrive& dd) : b(bb), d(dd) {}
    std::error_code enable(bool on) override { return d.enable(on); }
    std::error_code set_torque_Nm(double v) override { return d.set_torque_Nm(v); }
    std::error_code reset_fault() override { return d.reset_fault(); }
    std::error_code read(drivers::LoadTelemetry& out) override {
      b.maybe_slow();
      return d.read(out);
    }
    std::error_code read_window(drivers::LoadWindow& out) override { return d.read_window(out); }
  };
  emulator::TwinBench twin_;
  BenchDescription description_;
  Synrm synrm_;
  Load load_;
};

// An E-stop is answered once both disables were tried, before the tick's reads (which a starved
// line can stretch to seconds), and its answer says per drive what became of the disable; the
// status says "confirmed" once the read-back has seen both stopped.
TEST(BenchRuntime, AnEstopIsAnsweredAfterItsDisablesNotAfterTheReads) {
  auto owned = std::make_unique<SlowReadsAfterDisable>();
  SlowReadsAfterDisable* backend = owned.get();
  BenchRuntime rt(std::move(owned));
  rt.start();
  Answers a;
  rt.set_setpoints({300.0, 0.0, 50.0}, a.done("setpoints"));
  rt.enable(true, a.done("enable"));
  ASSERT_TRUE(wait_for([&] { return a.size() == 2; }, 5.0));
  ASSERT_FALSE(a.got[1].second.refusal);
  const auto sent = std::chrono::steady_clock::now();
  std::promise<Outcome> answered;
  rt.estop("test", [&](Outcome o) { answered.set_value(std::move(o)); });
  auto fut = answered.get_future();
  ASSERT_EQ(fut.wait_for(std::chrono::seconds(5)), std::future_status::ready);
  const double took_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
  EXPECT_LT(took_s, backend->slow_read_s.load()) << "answered without waiting on the reads";
  const Outcome o = fut.get();
  ASSERT_FALSE(o.refusal);
  const auto& d = o.snapshot->status.disable;
  ASSERT_TRUE(d);
  EXPECT_EQ(d->synrm.state, bench::DisableState::acknowledged);
  EXPECT_TRUE(d->synrm.first_acknowledged);
  EXPECT_EQ(d->load.state, bench::DisableState::acknowledged);
  EXPECT_FALSE(d->confirmed()) << "not read back yet: not claimed";
  EXPECT_EQ(o.snapshot->status.phase, bench::SafetyPhase::estopped);
  ASSERT_TRUE(wait_for([&] { return rt.snapshot()->status.disable && rt.snapshot()->status.disable->confirmed(); }, 5.0));
  backend->slow_read_s = 0;
  rt.shutdown();
}

// A plan's limits bind the daemon's sweep as they bind `synbench sweep`: 0.5 A trips a point
// that needs more, and the bench's own limits come back afterwards.
TEST(BenchRuntime, APlansStricterLimitsBindTheDaemonsSweep) {
  const auto dir = std::filesystem::temp_directory_path() / ("synbench_app_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto db_path = dir / "sweeps.db";
  std::int64_t id = 0;
  bench::SweepPlan plan;
  {
    auto parsed = bench::parse_sweep_plan(synbench::Json::parse(R"({"name": "strict", "window_s": 0.2,
        "dimensions": {"speed_rpm": [300], "load_Nm": [1.5], "angle_deg": [50]}, "limits": {"max_current_A": 0.5}})"));
    ASSERT_TRUE(parsed.plan) << (parsed.errors.empty() ? "" : parsed.errors[0].reason);
    plan = *parsed.plan;
    auto store = db::Store::open(db_path);
    ASSERT_TRUE(store);
    db::SweepMeta meta;
    meta.name = "strict";
    meta.plan = bench::to_json(plan);
    meta.total_points = 1;
    auto created = store->create_sweep(meta);
    ASSERT_TRUE(created);
    id = *created;
  }
  BenchRuntime rt(std::make_unique<TwinBackend>());
  const double bench_limit_A = rt.description().limits.max_current_A;
  rt.start();
  Answers a;
  rt.start_sweep(id, plan, {}, db_path, a.done("start"));
  ASSERT_TRUE(wait_for([&] { return a.size() == 1; }, 5.0));
  ASSERT_FALSE(a.got[0].second.refusal) << a.got[0].second.refusal->message;
  ASSERT_TRUE(wait_for([&] { auto s = rt.snapshot(); return s->status.sweep && s->status.sweep->state == "faulted"; }, 30.0));
  const auto s = rt.snapshot()->status;
  ASSERT_TRUE(s.trip);
  EXPECT_EQ(s.trip->fault, drivers::Fault::overcurrent) << s.trip->detail;
  EXPECT_NE(s.trip->detail.find("0.50 A"), std::string::npos) << s.trip->detail;
  EXPECT_GT(bench_limit_A, 1.0) << "the bench alone would have let the point run";
  rt.shutdown();
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace synbench::app
