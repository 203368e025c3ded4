// `synbench study`: twin studies (docs/study.md). `run` runs one shard's samples on the
// in-process twin, each with its plant deviation, into the store; `status` counts samples per
// shard; `analyse` merges every shard's points into one result.
#include "drivers/json.hpp"

#include <atomic>
#include <csignal>
#include <fstream>
#include <iostream>

#include "app/bench_backend.hpp"
#include "app/study_run.hpp"
#include "bench/study_analysis.hpp"
#include "bench/study_plan.hpp"
#include "db/store.hpp"
#include "drivers/json_file.hpp"
#include "emulator/plant_deviation.hpp"
#include "emulator/twin_config_schema.hpp"
#include "server/cli/args.hpp"
#include "server/cli/bench_setup.hpp"
#include "server/cli/commands.hpp"
#include "server/cli/db_log.hpp"

namespace synbench::cli {

const char* const kStudyHelp = R"(usage: synbench study run PLAN.json --shard K/N [options]
       synbench study status PLAN.json [options]
       synbench study analyse PLAN.json [options]

A twin study (docs/study.md) crosses a sweep plan with deviations of the twin's plant (Ld, Lq,
Rs, J, encoder offset, meter calibration) as a grid or a seeded Monte Carlo; the estimators keep
their nominal model. Sample i's sweep is stored under the key NAME/PLAN-HASH/i, so every shard of
a cluster job writes into one database and re-running a shard (or a killed one) resumes each
sample at its first missing point, never storing a point twice.

run: the samples i with i % N == K, one after another, on the in-process twin (virtual time).
  --shard K/N         this process's shard (0 <= K < N); required
  --db TARGET         the store (default synbench.db)
  --config FILE       the nominal twin config (docs/emulator-config.md); deviations apply on top
  --dry-run           check the plan and the shard, list the shard's samples; no store opened
  --quiet             no line per sample
status: samples done, running, stopped (incomplete) and missing, per shard.
  --db TARGET, --shards N (default 1), --json
analyse: the merged result per parameter value (grid) or bin (Monte Carlo) and configuration.
  --db TARGET, --json-out FILE (the result as JSON), --bins N (Monte Carlo bins, default 8)

exit status: 0 every sample of the shard complete, 1 a sample failed, 2 bad input,
130 interrupted (SIGINT/SIGTERM: the running sample stops in order and resumes on the next run)
)";

namespace {

std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

bench::StudyPlan load_plan(const std::string& file) {
  const drivers::JsonParsed read = drivers::read_json_file(file);
  if (!read.ok()) throw UsageError("PLAN.json", read.error);
  auto parsed = bench::parse_study_plan(read.doc);
  if (!parsed.plan) {
    std::string all;
    for (const auto& e : parsed.errors) all += "\n  " + bench::to_string(e);
    throw UsageError(file, "the study plan is refused:" + all);
  }
  return std::move(*parsed.plan);
}

std::string deviation_text(const bench::StudySample& s) {
  std::string out;
  for (const auto& [p, v] : s.deviation) out += (out.empty() ? "" : " ") + std::string(bench::name(p)) + "=" + synbench::Json(v).dump();
  return out;
}

// The twin of one sample: the nominal config with the sample's deviation on its plant.
std::optional<emulator::TwinConfig> sample_config(const emulator::TwinConfig& nominal, const bench::StudySample& s,
                                                  std::string& error) {
  emulator::TwinConfig c = nominal;
  for (const auto& [p, v] : s.deviation)
    if (auto e = emulator::apply_plant_deviation(c, bench::name(p), v)) {
      error = *e;
      return std::nullopt;
    }
  if (s.noise_seed_offset)
    c.sim.seed_int = static_cast<int>((static_cast<long long>(c.sim.seed_int) + *s.noise_seed_offset) % 2147483647LL);
  return c;
}

std::optional<db::Store> open_store(const std::string& target) {
  db::StoreOptions o;
  o.on_error = db_error_logger("synbench study: ");
  auto opened = db::Store::open(target, o);
  if (!opened) {
    std::cerr << "synbench study: --db: " << opened.error().message << "\n";
    return std::nullopt;
  }
  return std::move(*opened);
}

// The store with the study's sweeps in it (sample index -> sweep), or nothing after saying why.
struct StudyInStore {
  db::Store store;
  std::map<std::size_t, db::Sweep> sweeps;
};
std::optional<StudyInStore> open_study(const bench::StudyPlan& plan, const std::string& db_target) {
  auto store = open_store(db_target);
  if (!store) return std::nullopt;
  auto sweeps = app::study_sweeps(*store, plan);
  if (!sweeps) {
    std::cerr << "synbench study: " << sweeps.error().message << "\n";
    return std::nullopt;
  }
  return StudyInStore{std::move(*store), std::move(*sweeps)};
}

int run(const bench::StudyPlan& plan, bench::Shard shard, const std::string& db_target,
        const emulator::TwinConfig& nominal, bool dry_run, bool quiet) {
  const auto mine = bench::shard_samples(plan, shard);
  if (dry_run) {
    std::cout << "study " << plan.name << " (" << bench::plan_hash(plan) << "): shard " << shard.index << "/"
              << shard.count << ": " << mine.size() << " of " << bench::sample_count(plan) << " samples, "
              << bench::estimate(plan.sweep).points << " points each, into " << db::shown_target(db_target) << "\n";
    for (auto i : mine) {
      const auto s = bench::sample(plan, i);
      std::string error;
      if (!sample_config(nominal, s, error)) {
        std::cerr << "synbench study: sample " << i << ": " << error << "\n";
        return 2;
      }
      std::cout << s.key << " " << deviation_text(s) << "\n";
    }
    return 0;
  }
  auto store = open_store(db_target);
  if (!store) return 1;
  app::StudyShardOptions options;
  options.make_backend = [&](const bench::StudySample& s, std::string& error) -> std::unique_ptr<app::BenchBackend> {
    auto c = sample_config(nominal, s, error);
    if (!c) return nullptr;
    return make_backend(std::nullopt, *c);
  };
  options.bench_config = [&](const bench::StudySample& s) {
    std::string error;
    auto c = sample_config(nominal, s, error);
    return c ? emulator::to_json(*c) : synbench::Json();
  };
  g_stop = false;
  options.interrupted = [] { return g_stop.load(); };
  auto prev_int = std::signal(SIGINT, on_signal);
  auto prev_term = std::signal(SIGTERM, on_signal);
  if (!quiet)
    std::cerr << "study " << plan.name << ": shard " << shard.index << "/" << shard.count << ", " << mine.size()
              << " samples into " << db::shown_target(db_target) << "\n";
  const auto report = app::run_study_shard(*store, plan, shard, options, [&](const app::StudySampleOutcome& o) {
    if (quiet && o.error.empty()) return;
    std::cerr << "sample " << o.index << " (" << o.key << ", sweep " << o.sweep_id << "): " << app::name(o.result)
              << ", " << o.points_after << " points (" << o.points_before << " before this run)"
              << (o.error.empty() ? "" : ": " + o.error) << "\n";
  });
  std::signal(SIGINT, prev_int);
  std::signal(SIGTERM, prev_term);
  if (report.interrupted) return 130;
  return report.ok() ? 0 : 1;
}

int status(const bench::StudyPlan& plan, const std::string& db_target, std::size_t shards, bool as_json) {
  auto study = open_study(plan, db_target);
  if (!study) return 1;
  const auto& sweeps = study->sweeps;
  struct Counts {
    std::size_t samples = 0, done = 0, running = 0, stopped = 0, missing = 0;
    std::int64_t points = 0;
  };
  std::vector<Counts> per(shards);
  for (std::size_t i = 0; i < bench::sample_count(plan); ++i) {
    Counts& c = per[i % shards];
    ++c.samples;
    const auto it = sweeps.find(i);
    if (it == sweeps.end()) {
      ++c.missing;
      continue;
    }
    c.points += it->second.points_stored;
    if (it->second.state == db::SweepState::completed) ++c.done;
    else if (it->second.state == db::SweepState::running) ++c.running;
    else ++c.stopped;
  }
  if (as_json) {
    synbench::Json j{{"study", plan.name}, {"plan_hash", bench::plan_hash(plan)}, {"samples", bench::sample_count(plan)}};
    synbench::Json list = synbench::Json::array();
    for (std::size_t k = 0; k < shards; ++k)
      list.push_back({{"shard", std::to_string(k) + "/" + std::to_string(shards)}, {"samples", per[k].samples},
                      {"done", per[k].done}, {"running", per[k].running}, {"stopped", per[k].stopped},
                      {"missing", per[k].missing}, {"points", per[k].points}});
    j["shards"] = list;
    std::cout << j.dump(1) << "\n";
    return 0;
  }
  std::cout << "study " << plan.name << " (" << bench::plan_hash(plan) << "): " << bench::sample_count(plan)
            << " samples\nshard      samples     done  running  stopped  missing   points\n";
  for (std::size_t k = 0; k < shards; ++k) {
    char line[160];
    std::snprintf(line, sizeof line, "%-9s %8zu %8zu %8zu %8zu %8zu %8lld\n",
                  (std::to_string(k) + "/" + std::to_string(shards)).c_str(), per[k].samples, per[k].done,
                  per[k].running, per[k].stopped, per[k].missing, static_cast<long long>(per[k].points));
    std::cout << line;
  }
  return 0;
}

int analyse(const bench::StudyPlan& plan, const std::string& db_target, const std::optional<std::string>& json_out,
            std::size_t bins) {
  auto study = open_study(plan, db_target);
  if (!study) return 1;
  auto& store = study->store;
  const auto& sweeps = study->sweeps;
  std::vector<bench::StudySampleRecords> samples;
  for (const auto& [i, sweep] : sweeps) {
    auto rows = store.points(sweep.id);
    if (!rows) {
      std::cerr << "synbench study: " << rows.error().message << "\n";
      return 1;
    }
    bench::StudySampleRecords s{bench::sample(plan, i), {}};
    for (auto& r : *rows) s.records.push_back(std::move(r.record));
    samples.push_back(std::move(s));
  }
  const auto result = bench::analyze_study(plan, samples, bins);
  std::cout << bench::study_table(result);
  if (json_out) {
    std::ofstream out(*json_out);
    out << bench::to_json(result).dump(1) << "\n";
    if (!out) {
      std::cerr << "synbench study: --json: cannot write '" << *json_out << "'\n";
      return 1;
    }
  }
  return 0;
}

}  // namespace

int study_command(const std::vector<std::string>& argv) {
  try {
    if (argv.empty()) throw UsageError("study", "needs run, status or analyse (see synbench study --help)");
    const std::string sub = argv.front();
    if (sub == "--help" || sub == "-h") {
      std::cout << kStudyHelp;
      return 0;
    }
    if (sub != "run" && sub != "status" && sub != "analyse" && sub != "analyze")
      throw UsageError(sub, "unknown study command (expected run, status or analyse)");
    const std::vector<std::string> rest(argv.begin() + 1, argv.end());
    Args a(rest, {"--dry-run", "--quiet", "--json", "--help"},
           {"--shard", "--db", "--config", "--shards", "--bins", "--json-out"});
    if (a.has("--help")) {
      std::cout << kStudyHelp;
      return 0;
    }
    if (a.positional().size() != 1) throw UsageError("PLAN.json", "exactly one study plan file is required");
    const bench::StudyPlan plan = load_plan(a.positional().front());
    const std::string db_target = a.text("--db").value_or("synbench.db");
    if (sub == "run") {
      const auto shard_text = a.text("--shard");
      if (!shard_text) throw UsageError("--shard", "required: K/N, this process's shard");
      std::string reason;
      const auto shard = bench::parse_shard(*shard_text, &reason);
      if (!shard) throw UsageError("--shard", reason);
      emulator::TwinConfig nominal;
      if (auto file = a.text("--config")) nominal = emulator::load_twin_config_file(*file);
      return run(plan, *shard, db_target, nominal, a.has("--dry-run"), a.has("--quiet"));
    }
    if (sub == "status") {
      std::size_t shards = 1;
      if (auto n = a.number("--shards")) {
        if (*n < 1 || *n > 100000 || *n != std::floor(*n)) throw UsageError("--shards", "must be a whole number in 1..100000");
        shards = static_cast<std::size_t>(*n);
      }
      return status(plan, db_target, shards, a.has("--json"));
    }
    std::size_t bins = 8;
    if (auto n = a.number("--bins")) {
      if (*n < 1 || *n > 1000 || *n != std::floor(*n)) throw UsageError("--bins", "must be a whole number in 1..1000");
      bins = static_cast<std::size_t>(*n);
    }
    return analyse(plan, db_target, a.text("--json-out"), bins);
  } catch (const UsageError& e) {
    std::cerr << "synbench study: " << e.what() << "\n";
    return 2;
  } catch (const emulator::ConfigError& e) {
    std::cerr << "synbench study: --config: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace synbench::cli
