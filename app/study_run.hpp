// One shard of a twin study run into the store (docs/study.md): each of the shard's samples is
// one store sweep named by its deterministic key; a completed sweep is skipped, an incomplete one
// (a killed or interrupted run) resumes at its first missing point, a missing one is created. So
// re-running a shard, or running it after a kill, never stores a point twice. Every sample runs
// on its own bench backend (the twin with the sample's plant deviation, built by the caller:
// app/ stays free of the twin) through the same SweepRun as `synbench sweep`.
#pragma once

#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "app/bench_backend.hpp"
#include "bench/study_plan.hpp"
#include "bench/sweep_engine.hpp"
#include "db/store.hpp"

namespace synbench::app {

// The study's sweeps in the store by sample index (sweeps whose key has the plan's prefix).
// One listing, not a find_sweep_by_key per sample: `status` and `analyse` need them all.
db::Result<std::map<std::size_t, db::Sweep>> study_sweeps(db::Store& store, const bench::StudyPlan& plan);

struct StudyShardOptions {
  // The bench of one sample; nullptr with `error` set when the deviation cannot be applied.
  std::function<std::unique_ptr<BenchBackend>(const bench::StudySample&, std::string& error)> make_backend;
  // What is stored as the sample's bench_config (the twin config as deviated).
  std::function<synbench::Json(const bench::StudySample&)> bench_config;
  // Asked every tick; true aborts the running sample in order (it resumes on the next run).
  std::function<bool()> interrupted;
  bench::SweepSink* observer = nullptr;  // told of every committed point
};

enum class StudySampleResult { already_complete, completed, failed, interrupted };
std::string_view name(StudySampleResult r);

struct StudySampleOutcome {
  std::size_t index = 0;
  std::string key;
  std::int64_t sweep_id = 0;
  StudySampleResult result = StudySampleResult::failed;
  std::size_t points_before = 0;  // stored before this run (a resumed sample)
  std::size_t points_after = 0;
  std::string error;
};

struct StudyShardReport {
  std::vector<StudySampleOutcome> samples;
  bool interrupted = false;
  bool ok() const;  // every sample complete
};

StudyShardReport run_study_shard(db::Store& store, const bench::StudyPlan& plan, bench::Shard shard,
                                 const StudyShardOptions& options,
                                 const std::function<void(const StudySampleOutcome&)>& on_sample = {});

}  // namespace synbench::app
