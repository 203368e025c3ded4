// A twin sweep on several cores (`synbench sweep --jobs N`): the plan's groups (the angle sweep
// at one speed, load and configuration) are shared out among N jobs, group g to job g % N, each
// job a thread that owns a twin of its own built from the same config, its own safety supervisor
// and its own sweep engine (bench/sweep_engine.hpp, keep_groups). The jobs never touch the store:
// they hand every measured point and event to the calling thread, the store's one owner, which
// writes the points in point order (a point waits until no running job can still measure a lower
// one) and draws the progress. Resumable as a serial sweep: a resume gives every job the stored
// points, each skips its own. A job that faults stops the others (aborted), and the sweep is
// faulted with its error; an interruption stops every job in order. What was measured is
// written before the call returns, in order; a crash loses the points still waiting for a lower
// one (at most a group's worth per job), which a resume measures again.
//
// Each job's twin starts at the config's initial state and its own noise sequence, so a point
// measured by a job is not bit-identical to the serial sweep's; the analysis agrees within its
// uncertainties (tests/server/sweep_test.py, docs/benchmarks.md).
#pragma once

#include <cstddef>
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

struct ParallelSweepOptions {
  std::size_t jobs = 2;
  // Builds one job's bench; called on the job's own thread (its twin is that thread's).
  std::function<std::unique_ptr<BenchBackend>()> make_backend;
  bench::SweepBench calibration;
  // Told of every written point, event and progress step, on the calling thread.
  bench::SweepSink* observer = nullptr;
  // Asked every few milliseconds on the calling thread; its first true stops every job in order
  // and calls on_abort.
  std::function<bool()> interrupted;
  std::function<void()> on_abort;
};

struct ParallelSweepResult {
  db::SweepState state = db::SweepState::completed;
  std::string error;                 // the faulted job's (or the store's) error; empty otherwise
  std::optional<std::string> alarm;  // a job's supervisor alarm: a drive that did not read back stopped
  std::size_t written = 0;           // points written by this run
  double bench_s = 0;                // the longest job's bench time
};

// Runs sweep `id` of `store` (its state set to running, then to the result's) on
// options.jobs twins. `stored`: the points already in the store (a resume).
ParallelSweepResult run_parallel_sweep(db::Store& store, std::int64_t id, const bench::SweepPlan& plan,
                                       const std::map<std::size_t, bench::PointRecord>& stored,
                                       const ParallelSweepOptions& options);

}  // namespace synbench::app
