// `synbench sweep`: runs a sweep plan headless on the in-process twin, every point committed to
// the SQLite store as it is measured; resumable after a crash or an abort; exports and analysis.
#include "drivers/json.hpp"

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <thread>
#include <unistd.h>

#include "bench/analysis.hpp"
#include "bench/sweep_outcome.hpp"
#include "bench/pace.hpp"
#include "bench/safety_supervisor.hpp"
#include "bench/sweep_engine.hpp"
#include "bench/sweep_plan.hpp"
#include "db/export.hpp"
#include "db/store.hpp"
#include "drivers/json_file.hpp"
#include "app/bench_backend.hpp"
#include "app/parallel_sweep.hpp"
#include "app/plan_needs.hpp"
#include "app/supervised_point.hpp"
#include "app/sweep_run.hpp"
#include "emulator/twin_config_schema.hpp"
#include "server/cli/args.hpp"
#include "server/cli/bench_setup.hpp"
#include "server/cli/commands.hpp"
#include "server/cli/db_log.hpp"

namespace synbench::cli {

const char* const kSweepHelp = R"(usage: synbench sweep PLAN.json [options]
       synbench sweep --resume ID [options]

Runs a sweep plan (docs/sweep-plan.md) headless on the in-process twin, on virtual time, as fast
as the CPU allows, or with --bench on the drives of a bench config (real drives, `synbench
emulate`) in real time. The safety supervisor watches every tick, on the stricter of the bench's
and the plan's limits, and stops the bench in order on any trip. Every measured point is
committed to the SQLite database before the next one starts; a sweep interrupted by a crash, a
fault or Ctrl-C resumes at its first missing point.

options:
  --db FILE|URL       database file (default synbench.db; created if missing), or a PostgreSQL
                      lab store: postgresql://user@host:port/db or host=/socket/dir dbname=db
                      (docs/database.md; its password is never printed)
  --resume ID         continue sweep ID from the database (its stored plan is used)
  --config FILE       twin config JSON (docs/emulator-config.md)
  --bench FILE        bench config JSON (docs/bench-config.md): its drives instead of the twin
  --jobs N            twin only: run the plan's groups (the angle sweep at one speed, load and
                      configuration) on N twins at once, one per core, each from the same config
                      (default: the machine's cores; 1: one twin, the serial sweep). The points
                      are written in point order by one writer; each job's twin has its own
                      noise sequence, so they are not bit-identical to a serial run's
  --bench-name NAME   this bench's name, stored with the sweep next to its host and device
                      profiles' versions (default: the host name; docs/database.md)
  --export-csv FILE   write the sweep's points as CSV when it ends
  --export-json FILE  write the sweep's points as JSON when it ends
  --analysis FILE     write the analysis (MTPA/ME angles, deltas, histograms, efficiency map) and the
                      sweep's outcome (adaptive searches, precision target) as JSON
  --dry-run           check the plan and print its bench-time estimate as JSON (as
                      POST /api/sweeps/estimate); nothing is measured or stored
  --quiet             no progress output
  --print-committed   print "committed INDEX" on stdout as each point's commit returns
  --help              this text

A progress bar with ETA is drawn on a terminal; otherwise a plain line every 10 s.
exit status: 0 completed, 1 faulted or failed, 2 bad input, 130 aborted (Ctrl-C)
)";

namespace {

std::atomic<bool> g_interrupted{false};
void on_sigint(int) { g_interrupted = true; }

std::string hms(double s) {
  const long t = static_cast<long>(s + 0.5);
  char buf[32];
  if (t >= 3600)
    std::snprintf(buf, sizeof buf, "%ldh%02ldm", t / 3600, (t / 60) % 60);
  else
    std::snprintf(buf, sizeof buf, "%ldm%02lds", t / 60, t % 60);
  return buf;
}

// Told by the sweep run of each committed point, event and progress step: draws progress.
class ProgressPrinter final : public bench::SweepSink {
 public:
  ProgressPrinter(std::int64_t sweep_id, bool quiet, bool print_committed)
      : id_(sweep_id), quiet_(quiet), print_committed_(print_committed),
        tty_(isatty(STDERR_FILENO) != 0),
        start_(std::chrono::steady_clock::now()) {}

  // Called once the point is committed.
  std::error_code store_point(std::size_t index, const bench::PointRecord&) override {
    if (print_committed_) {
      std::printf("committed %zu\n", index);
      std::fflush(stdout);
    }
    ++stored_this_run_;
    return {};
  }
  void event(const std::string& kind, const std::string& message) override {
    if (!quiet_ && (kind == "fault" || kind == "alarm")) std::cerr << (tty_ ? "\n" : "") << kind << ": " << message << "\n";
  }
  void progress(const bench::SweepProgress& p) override {
    if (quiet_) return;
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double frac = p.total ? static_cast<double>(p.done) / static_cast<double>(p.total) : 1.0;
    const auto left_s = bench::remaining_s(wall, stored_this_run_, p.done, p.total);
    const std::string eta = left_s ? hms(*left_s) : "-";
    if (tty_) {
      const int width = 30, fill = static_cast<int>(frac * width);
      std::fprintf(stderr, "\r[%s%s] %zu/%zu %3.0f%%  ETA %s  bench %s  %s   ",
                   std::string(static_cast<std::size_t>(fill), '#').c_str(),
                   std::string(static_cast<std::size_t>(width - fill), '.').c_str(), p.done, p.total,
                   100 * frac, eta.c_str(), hms(p.bench_elapsed_s).c_str(),
                   std::string(bench::name(p.state)).c_str());
    } else if (wall - last_line_ >= 10.0 || p.done == p.total) {
      last_line_ = wall;
      std::fprintf(stderr, "sweep %lld: %zu/%zu points (%.0f %%), ETA %s, bench time %s, %s\n",
                   static_cast<long long>(id_), p.done, p.total, 100 * frac, eta.c_str(),
                   hms(p.bench_elapsed_s).c_str(), std::string(bench::name(p.state)).c_str());
    }
  }
  void finish_line() const {
    if (!quiet_ && tty_) std::fprintf(stderr, "\n");
  }

 private:
  std::int64_t id_;
  bool quiet_, print_committed_, tty_;
  std::chrono::steady_clock::time_point start_;
  std::size_t stored_this_run_ = 0;
  double last_line_ = -1e9;
};

bool write_file(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  return static_cast<bool>(out);
}

}  // namespace

int sweep_command(const std::vector<std::string>& argv) {
  emulator::TwinConfig config;
  std::optional<bench::SweepPlan> plan;
  std::string db_path = "synbench.db";
  std::optional<std::int64_t> resume;
  std::optional<std::string> csv, json_out, analysis_out;
  bool quiet = false, print_committed = false, dry_run = false;
  std::optional<LoadedBench> loaded;
  std::string bench_file;
  std::string bench_name;
  std::size_t jobs = std::max(1u, std::thread::hardware_concurrency());
  try {
    Args a(argv, {"--quiet", "--print-committed", "--dry-run", "--help"},
           {"--db", "--resume", "--config", "--bench", "--export-csv", "--export-json", "--analysis", "--bench-name",
            "--jobs"});
    if (a.has("--help")) {
      std::cout << kSweepHelp;
      return 0;
    }
    quiet = a.has("--quiet");
    print_committed = a.has("--print-committed");
    dry_run = a.has("--dry-run");
    if (auto v = a.text("--db")) db_path = *v;
    if (auto v = a.text("--bench-name")) bench_name = *v;
    csv = a.text("--export-csv");
    json_out = a.text("--export-json");
    analysis_out = a.text("--analysis");
    if (auto file = a.text("--config")) config = emulator::load_twin_config_file(*file);
    if (auto file = a.text("--bench")) {
      loaded = load_bench_or_throw(*file, "--bench");
      bench_file = *file;
      if (!loaded->config.on_twin() && a.text("--config"))
        throw UsageError("--config", "configures the in-process twin, which this bench config does not use; give it to "
                                     "synbench emulate");
    }
    if (loaded) jobs = 1;  // a bench has one set of drives
    if (auto n = a.number("--jobs")) {
      if (*n < 1 || *n > 256 || *n != std::floor(*n)) throw UsageError("--jobs", "must be a whole number in 1..256");
      if (loaded && *n > 1)
        throw UsageError("--jobs", "runs several twins at once; a bench config's drives are one bench (leave --jobs out)");
      jobs = static_cast<std::size_t>(*n);
    }
    if (auto r = a.number("--resume")) {
      if (*r < 1 || *r != std::floor(*r)) throw UsageError("--resume", "must be a sweep id (a whole number >= 1)");
      resume = static_cast<std::int64_t>(*r);
      if (!a.positional().empty()) throw UsageError(a.positional().front(), "a resumed sweep uses its stored plan");
    } else {
      if (a.positional().size() != 1) throw UsageError("PLAN.json", "exactly one plan file is required");
      const std::string& file = a.positional().front();
      const drivers::JsonParsed read = drivers::read_json_file(file);
      if (!read.ok()) throw UsageError("PLAN.json", read.error);
      auto parsed = bench::parse_sweep_plan(read.doc);
      if (!parsed.errors.empty()) {
        for (const auto& e : parsed.errors) std::cerr << "synbench sweep: " << file << ": " << bench::to_string(e) << "\n";
        return 2;
      }
      plan = std::move(parsed.plan);
    }
  } catch (const UsageError& e) {
    std::cerr << "synbench sweep: " << e.what() << "\n";
    return 2;
  } catch (const emulator::ConfigError& e) {
    std::cerr << "synbench sweep: --config: " << e.what() << "\n";
    return 2;
  }

  if (dry_run) {
    if (!plan) {
      std::cerr << "synbench sweep: --dry-run: needs a plan file, not --resume\n";
      return 2;
    }
    std::cout << bench::to_json(bench::estimate(*plan)).dump(1) << "\n";
    return 0;
  }

  // A plan the bench's profiles cannot serve is refused before anything is stored (a resumed
  // plan is checked once read back, below).
  if (plan && loaded) {
    app::BenchDescription needs;
    if (!loaded->profiles.synrm_drive.find("temp_C")) needs.synrm_without_temperature = loaded->profiles.synrm_drive.name;
    if (auto unmet = app::unmet_plan_needs(*plan, needs)) {
      std::cerr << "synbench sweep: refused before the start: " << *unmet << "\n";
      return 2;
    }
  }

  // Checked before the bench moves: damaged pages and a file that cannot be written are refused.
  db::StoreOptions store_options;
  store_options.verify = true;
  store_options.on_error = db_error_logger("synbench sweep: ");
  store_options.bench = bench_identity(loaded, bench_name);
  auto opened = db::Store::open(db_path, store_options);
  if (!opened) {
    std::cerr << "synbench sweep: --db: " << opened.error().message << "\n";
    return 1;
  }
  db::Store store = std::move(*opened);

  std::int64_t id = 0;
  std::map<std::size_t, bench::PointRecord> stored;
  if (resume) {
    auto sweep = store.get_sweep(*resume);
    if (!sweep) {
      std::cerr << "synbench sweep: --resume " << *resume << ": " << sweep.error().message << "\n";
      return 2;
    }
    if (sweep->state == db::SweepState::completed) {
      std::cerr << "synbench sweep: --resume " << *resume << ": the sweep is already completed\n";
      return 2;
    }
    auto parsed = bench::parse_sweep_plan(sweep->meta.plan);
    if (!parsed.plan) {
      std::cerr << "synbench sweep: --resume " << *resume << ": its stored plan no longer parses: "
                << bench::to_string(parsed.errors.front()) << "\n";
      return 1;
    }
    plan = std::move(parsed.plan);
    auto rows = store.points(*resume);
    if (!rows) {
      std::cerr << "synbench sweep: " << rows.error().message << "\n";
      return 1;
    }
    for (const auto& row : *rows) stored[static_cast<std::size_t>(row.index)] = row.record;
    id = *resume;
  } else {
    db::SweepMeta meta;
    meta.name = plan->name.empty() ? "sweep" : plan->name;
    meta.plan = bench::to_json(*plan);
    if (loaded) {
      std::ifstream in(bench_file);
      meta.bench_config = {{"bench_file", bench_file}, {"bench", synbench::Json::parse(in, nullptr, false)}};
    } else {
      meta.bench_config = emulator::to_json(config);
    }
    const auto est = bench::estimate(*plan);
    meta.total_points = static_cast<std::int64_t>(est.points);
    auto created = store.create_sweep(meta);
    if (!created) {
      std::cerr << "synbench sweep: " << created.error().message << "\n";
      return 1;
    }
    id = *created;
  }
  if (!quiet)
    std::cerr << "sweep " << id << " (" << store.path().string() << "): " << stored.size() << " points stored before this run"
              << (jobs > 1 ? ", " + std::to_string(jobs) + " jobs" : std::string()) << "\n";

  auto backend = make_backend(std::move(loaded), config);
  const app::BenchDescription& bench = backend->description();
  if (auto unmet = app::unmet_plan_needs(*plan, bench)) {
    std::cerr << "synbench sweep: refused before the start: " << *unmet << "\n";
    return 1;
  }
  ProgressPrinter printer(id, quiet, print_committed);
  bench::SweepBench calibration;
  calibration.load_b1_Nms_per_rad = bench.load_b1_Nms_per_rad;
  calibration.uncertainty = bench.uncertainty;
  const auto on_abort = [&] {
    if (!quiet) std::cerr << "\ninterrupted: ordered stop, then the sweep can be resumed with --resume " << id << "\n";
  };
  db::SweepState final_state = db::SweepState::faulted;
  std::string engine_error;
  std::optional<std::string> alarm;
  g_interrupted = false;
  auto previous = std::signal(SIGINT, on_sigint);
  if (jobs > 1) {
    backend.reset();  // each job builds its own twin, on its own thread
    app::ParallelSweepOptions options;
    options.jobs = jobs;
    options.make_backend = [&config] { return make_backend(std::nullopt, config); };
    options.calibration = calibration;
    options.observer = &printer;
    options.interrupted = [] { return g_interrupted.load(); };
    options.on_abort = on_abort;
    const auto result = app::run_parallel_sweep(store, id, *plan, stored, options);
    final_state = result.state;
    engine_error = result.error;
    alarm = result.alarm;
  } else {
    bench::SafetySupervisor supervisor(backend->devices(), bench.limits, [&](const std::string& k, const std::string& m) {
      (void)store.add_event(id, app::sweep_event_kind(k), m);
      if (!quiet && k == "alarm") std::cerr << "ALARM: " << m << "\n";
    });
    app::SweepRunOptions run_options;
    run_options.calibration = calibration;
    run_options.observer = &printer;
    // The same runner as the daemon's: the stricter of the bench's and the plan's limits.
    app::SweepRun run(backend->devices(), supervisor, store, id, *plan, std::move(stored), run_options);
    if (auto e = run.begin()) {
      std::signal(SIGINT, previous);
      std::cerr << "synbench sweep: " << *e << "\n";
      return 1;
    }
    app::run_to_end(*backend, supervisor, run.engine(), bench.poll_period_s, [] { return g_interrupted.load(); }, on_abort);
    final_state = run.final_state();
    if (auto e = run.finish()) std::cerr << "synbench sweep: recording the final state: " << *e << "\n";
    engine_error = run.engine().error();
    if (supervisor.alarm()) alarm = supervisor.alarm()->detail;
  }
  std::signal(SIGINT, previous);
  printer.finish_line();

  auto rows = store.points(id);
  if (!rows) {
    std::cerr << "synbench sweep: " << rows.error().message << "\n";
    return 1;
  }
  int status = final_state == db::SweepState::completed ? 0 : final_state == db::SweepState::aborted ? 130 : 1;
  if (alarm) {
    std::cerr << "synbench sweep: ALARM: " << *alarm << "\n";
    status = 1;
  }
  if (csv && !write_file(*csv, db::points_to_csv(*rows))) {
    std::cerr << "synbench sweep: --export-csv: cannot write '" << *csv << "'\n";
    status = 1;
  }
  if (json_out && !write_file(*json_out, db::points_to_json(*rows).dump(1) + "\n")) {
    std::cerr << "synbench sweep: --export-json: cannot write '" << *json_out << "'\n";
    status = 1;
  }
  std::map<std::size_t, bench::PointRecord> by_index;
  for (const auto& r : *rows) by_index[static_cast<std::size_t>(r.index)] = r.record;
  const auto outcome = bench::sweep_outcome(*plan, by_index);
  if (!quiet) std::cerr << bench::to_text(outcome);
  if (analysis_out) {
    std::vector<bench::PointRecord> records;
    for (const auto& r : *rows) records.push_back(r.record);
    auto analysis = bench::to_json(bench::analyze(records));
    analysis["sweep_outcome"] = bench::to_json(outcome);
    if (!write_file(*analysis_out, analysis.dump(1) + "\n")) {
      std::cerr << "synbench sweep: --analysis: cannot write '" << *analysis_out << "'\n";
      status = 1;
    }
  }
  if (!quiet)
    std::cerr << "sweep " << id << " " << db::name(final_state) << ": " << rows->size() << " points in " << store.path().string()
              << (engine_error.empty() ? "" : " (" + engine_error + ")") << "\n";
  return status;
}

}  // namespace synbench::cli
