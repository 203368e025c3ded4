// One sweep of the store run on a bench under its safety supervisor: the engine, a sink that
// commits every point before the next one starts, the plan's limits applied to the supervisor
// (the stricter of the bench's and the plan's), and the sweep's state in the store from running
// to its end. `synbench sweep` ticks it in its own loop, the daemon on its bench thread: the
// same code on every path.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "app/bench_backend.hpp"
#include "bench/safety_supervisor.hpp"
#include "bench/sweep_engine.hpp"
#include "db/store.hpp"

namespace synbench::app {

struct SweepRunOptions {
  bench::SweepBench calibration;
  // Told of every committed point, event and progress step (a progress bar, a log).
  bench::SweepSink* observer = nullptr;
};

class SweepRun {
 public:
  SweepRun(drivers::BenchDevices devices, bench::SafetySupervisor& supervisor, db::Store& store, std::int64_t id,
           bench::SweepPlan plan, std::map<std::size_t, bench::PointRecord> stored, SweepRunOptions options = {});
  // Gives the supervisor its own limits back.
  ~SweepRun();
  SweepRun(const SweepRun&) = delete;
  SweepRun& operator=(const SweepRun&) = delete;

  // Records the sweep as running: the store's message when it cannot (nothing has moved then).
  std::optional<std::string> begin();
  // Call after the supervisor's tick, with the same time.
  void tick(double now_s) { engine_->tick(now_s); }
  bool finished() const { return engine_->finished(); }
  // Records the final state with the engine's error; the store's message when that failed.
  std::optional<std::string> finish();
  db::SweepState final_state() const;

  bench::SweepEngine& engine() { return *engine_; }
  const bench::SweepEngine& engine() const { return *engine_; }
  std::int64_t id() const { return id_; }

 private:
  class Sink;
  bench::SafetySupervisor& supervisor_;
  bench::SafetyLimits bench_limits_;
  db::Store& store_;
  std::int64_t id_;
  bool sparse_;
  std::unique_ptr<Sink> sink_;
  std::unique_ptr<bench::SweepEngine> engine_;
};

// The store's kind of a sweep event the engine or the supervisor names: "fault" and "alarm" are
// faults, "state" a state change, anything else a log line.
db::EventKind sweep_event_kind(const std::string& kind);

// A headless run (`synbench sweep`, `synbench study run`): ticks the bench, the supervisor and the
// sweep every `tick_s` of the backend's clock until the sweep ends, then confirms both drives read
// back stopped. `interrupted` is asked every tick; its first true aborts the sweep (ordered stop,
// resumable) and calls `on_abort`. Returns the time reached.
double run_to_end(BenchBackend& backend, bench::SafetySupervisor& supervisor, bench::SweepEngine& engine, double tick_s,
                  const std::function<bool()>& interrupted = {}, const std::function<void()>& on_abort = {});

}  // namespace synbench::app
