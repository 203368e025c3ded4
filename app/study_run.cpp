// A shard of a twin study into the store; see study_run.hpp.
#include "app/study_run.hpp"

#include "drivers/json.hpp"

#include "app/plan_needs.hpp"
#include "app/sweep_run.hpp"

namespace synbench::app {
namespace {

synbench::Json deviation_json(const bench::StudySample& s) {
  synbench::Json d = synbench::Json::object();
  for (const auto& [p, v] : s.deviation) d[std::string(bench::name(p))] = v;
  return d;
}

db::SweepMeta sample_meta(const bench::StudyPlan& plan, const bench::StudySample& s, const StudyShardOptions& o) {
  db::SweepMeta meta;
  meta.name = s.key;
  meta.key = s.key;  // unique in the store: two runs of one shard cannot both create the sample
  meta.plan = bench::to_json(plan.sweep);
  meta.bench_config = o.bench_config ? o.bench_config(s) : synbench::Json();
  synbench::Json study{{"name", plan.name},
                       {"plan_hash", bench::plan_hash(plan)},
                       {"sample", s.index},
                       {"key", s.key},
                       {"deviation", deviation_json(s)}};
  if (s.noise_seed_offset) study["noise_seed_offset"] = *s.noise_seed_offset;
  meta.calibration = {{"study", study}};
  meta.total_points = static_cast<std::int64_t>(bench::estimate(plan.sweep).points);
  return meta;
}

}  // namespace

std::string_view name(StudySampleResult r) {
  switch (r) {
    case StudySampleResult::already_complete: return "already complete";
    case StudySampleResult::completed: return "completed";
    case StudySampleResult::interrupted: return "interrupted";
    default: return "failed";
  }
}

bool StudyShardReport::ok() const {
  for (const auto& s : samples)
    if (s.result != StudySampleResult::already_complete && s.result != StudySampleResult::completed) return false;
  return !interrupted;
}

db::Result<std::map<std::size_t, db::Sweep>> study_sweeps(db::Store& store, const bench::StudyPlan& plan) {
  auto all = store.list_sweeps();
  if (!all) return all.error();
  std::map<std::size_t, db::Sweep> out;
  for (auto& s : *all) {
    if (!s.meta.key) continue;
    if (const auto i = bench::sample_index(plan, *s.meta.key)) out.emplace(*i, std::move(s));
  }
  return out;
}

StudyShardReport run_study_shard(db::Store& store, const bench::StudyPlan& plan, bench::Shard shard,
                                 const StudyShardOptions& options,
                                 const std::function<void(const StudySampleOutcome&)>& on_sample) {
  StudyShardReport report;
  auto existing = study_sweeps(store, plan);
  for (const std::size_t index : bench::shard_samples(plan, shard)) {
    const bench::StudySample s = bench::sample(plan, index);
    StudySampleOutcome out;
    out.index = index;
    out.key = s.key;
    auto done = [&] {
      if (on_sample) on_sample(out);
      report.samples.push_back(out);
    };
    if (!existing) {
      out.error = existing.error().message;
      done();
      continue;
    }
    if (options.interrupted && options.interrupted()) {
      report.interrupted = true;
      break;
    }
    std::map<std::size_t, bench::PointRecord> stored;
    if (auto it = existing->find(index); it != existing->end()) {
      out.sweep_id = it->second.id;
      if (it->second.state == db::SweepState::completed) {
        out.result = StudySampleResult::already_complete;
        out.points_before = out.points_after = static_cast<std::size_t>(it->second.points_stored);
        done();
        continue;
      }
      auto rows = store.points(out.sweep_id);
      if (!rows) {
        out.error = rows.error().message;
        done();
        continue;
      }
      for (const auto& row : *rows) stored[static_cast<std::size_t>(row.index)] = row.record;
    } else {
      auto created = store.create_sweep(sample_meta(plan, s, options));
      if (!created && created.error().code == db::make_error_code(db::errc::duplicate_key)) {
        // Another process created it since the listing (the same shard run twice at once): its run.
        out.error = "another process is running this sample: " + created.error().message;
        done();
        continue;
      }
      if (!created) {
        out.error = created.error().message;
        done();
        continue;
      }
      out.sweep_id = *created;
    }
    out.points_before = stored.size();

    auto backend = options.make_backend(s, out.error);
    if (!backend) {
      (void)store.add_event(out.sweep_id, db::EventKind::fault, "study sample not run: " + out.error);
      done();
      continue;
    }
    const BenchDescription& bench = backend->description();
    if (auto unmet = unmet_plan_needs(plan.sweep, bench)) {
      out.error = *unmet;
      done();
      continue;
    }
    const std::int64_t id = out.sweep_id;
    bench::SafetySupervisor supervisor(backend->devices(), bench.limits, [&](const std::string& k, const std::string& m) {
      (void)store.add_event(id, k == "fault" || k == "alarm" ? db::EventKind::fault : db::EventKind::state, m);
    });
    SweepRunOptions run_options;
    run_options.calibration.load_b1_Nms_per_rad = bench.load_b1_Nms_per_rad;
    run_options.calibration.uncertainty = bench.uncertainty;
    run_options.observer = options.observer;
    SweepRun run(backend->devices(), supervisor, store, id, plan.sweep, std::move(stored), run_options);
    if (auto e = run.begin()) {
      out.error = *e;
      done();
      continue;
    }
    bool aborted = false;
    run_to_end(*backend, supervisor, run.engine(), bench.poll_period_s, options.interrupted, [&] { aborted = true; });
    const auto final_state = run.final_state();
    if (auto e = run.finish()) out.error = *e;
    if (out.error.empty()) out.error = run.engine().error();
    if (supervisor.alarm()) out.error = "ALARM: " + supervisor.alarm()->detail;
    auto after = store.get_sweep(id);
    if (after) out.points_after = static_cast<std::size_t>(after->points_stored);
    out.result = final_state == db::SweepState::completed && !supervisor.alarm() ? StudySampleResult::completed
                 : aborted                                                         ? StudySampleResult::interrupted
                                                                                   : StudySampleResult::failed;
    done();
    if (aborted) {
      report.interrupted = true;
      break;
    }
  }
  return report;
}

}  // namespace synbench::app
