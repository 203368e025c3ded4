// Benchmark: one sensorless configuration through the thesis grid as `synbench sweep` runs it:
// bench::SweepEngine on one in-process twin (the drives kept running, speed > load > angle, the
// gate deciding when a point has settled, the thermal precondition, the restart after a lost
// speed), with the records kept in memory instead of SQLite. A fresh twin per point
// (estimator_grid) hides what a sweep meets: the observer must carry its lock through every
// setpoint change. Prints per-speed counts of points, points flagged unstable, points the drive's
// lock guard ran on the encoder, points out of lock (position-error span over 90 deg: a slipping
// observer sweeps the whole (-90, 90] deg), the worst |mean position error| in lock, the mean
// settling time, the points an EEMF's low-speed fallback gave the angle for part of the window
// and the largest such part, the restarts, the sweep's end state and the wall time. Exits 1
// when the sweep does not complete.
// usage: estimator_chain --estimator NAME [--pwm capwm|aspwm] [--speeds a,b,..] [--loads ..]
//                        [--angles ..] [--timeout-s S] [--config FILE] [--verbose]
//   defaults: the thesis-grid preset (EEMF variants from 500 rpm, HFI up to 300 rpm), the thesis
//   PWM of the estimator, the plan's gate timeout.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <map>
#include <string>
#include <vector>

#include "drivers/json.hpp"

#include "bench/safety_supervisor.hpp"
#include "bench/sweep_engine.hpp"
#include "bench/sweep_plan.hpp"
#include "emulator/twin_bench.hpp"
#include "emulator/twin_config_schema.hpp"

namespace {

using synbench::drivers::Estimator;
using synbench::drivers::Pwm;

std::vector<double> list(const char* s) {
  std::vector<double> v;
  for (char* end = nullptr; *s; s = (*end == ',') ? end + 1 : end) {
    v.push_back(std::strtod(s, &end));
    if (end == s) break;
  }
  return v;
}

struct Tally {
  int points = 0, unstable = 0, lock_lost = 0, out_of_lock = 0, on_fallback = 0;
  double worst_in_lock_deg = 0, settle_sum_s = 0, max_fallback = 0;
};

struct RecordSink : synbench::bench::SweepSink {
  std::vector<synbench::bench::PointRecord> records;
  int restarts = 0;
  std::error_code store_point(std::size_t, const synbench::bench::PointRecord& r) override {
    records.push_back(r);
    return {};
  }
  void event(const std::string& kind, const std::string& message) override {
    // The engine logs each point whose speed was lost before it restarts the drives.
    if (kind == "log" && message.find("restarting the drives") != std::string::npos) ++restarts;
  }
};

}  // namespace

int main(int argc, char** argv) {
  Estimator e = Estimator::encoder;  // encoder: none given (or a bad argument)
  std::optional<Pwm> pwm;
  std::vector<double> speeds, loads, angles;
  std::optional<double> timeout_s;
  const char* config_path = nullptr;
  bool verbose = false;
  for (int i = 1; i < argc; ++i) {
    const bool has_value = i + 1 < argc;
    if (!std::strcmp(argv[i], "--estimator") && has_value) {
      e = synbench::drivers::parse_estimator(argv[++i]).value_or(Estimator::encoder);
    } else if (!std::strcmp(argv[i], "--pwm") && has_value) {
      pwm = synbench::drivers::parse_pwm(argv[++i]);
      if (!pwm) e = Estimator::encoder;
    } else if (!std::strcmp(argv[i], "--speeds") && has_value) {
      speeds = list(argv[++i]);
    } else if (!std::strcmp(argv[i], "--loads") && has_value) {
      loads = list(argv[++i]);
    } else if (!std::strcmp(argv[i], "--angles") && has_value) {
      angles = list(argv[++i]);
    } else if (!std::strcmp(argv[i], "--timeout-s") && has_value) {
      timeout_s = std::strtod(argv[++i], nullptr);
    } else if (!std::strcmp(argv[i], "--config") && has_value) {
      config_path = argv[++i];
    } else if (!std::strcmp(argv[i], "--verbose")) {
      verbose = true;
    } else {
      e = Estimator::encoder;
      break;
    }
  }
  if (e == Estimator::encoder) {
    std::fprintf(stderr,
                 "usage: %s --estimator NAME [--pwm capwm|aspwm] [--speeds a,b,..] [--loads ..] "
                 "[--angles ..] [--timeout-s S] [--config FILE] [--verbose]\n  NAME: a sensorless estimator "
                 "(ekf-basic, ekf-rs, hfi, eemf-const, eemf-lut, eemf-rls)\n",
                 argv[0]);
    return 2;
  }
  const bool ekf = e == Estimator::ekf_basic || e == Estimator::ekf_rs;
  if (!pwm) pwm = ekf ? Pwm::aspwm : Pwm::capwm;

  synbench::emulator::TwinConfig cfg;
  try {
    if (config_path) cfg = synbench::emulator::load_twin_config_file(config_path);
  } catch (const std::exception& ex) {
    std::fprintf(stderr, "%s\n", ex.what());
    return 2;
  }
  // The thesis-grid preset with this one configuration; the dimensions given replace the
  // preset's, as in a plan file.
  synbench::Json doc = {{"name", "estimator chain"},
                        {"preset", "thesis-grid"},
                        {"dimensions",
                         {{"configurations",
                           {{{"estimator", synbench::drivers::name(e)}, {"pwm", synbench::drivers::name(*pwm)}}}}}}};
  if (!speeds.empty()) doc["dimensions"]["speed_rpm"] = speeds;
  if (!loads.empty()) doc["dimensions"]["load_Nm"] = loads;
  if (!angles.empty()) doc["dimensions"]["angle_deg"] = angles;
  if (timeout_s) doc["gate"]["timeout_s"] = *timeout_s;
  auto parsed = synbench::bench::parse_sweep_plan(doc);
  if (!parsed.errors.empty()) {
    std::fprintf(stderr, "plan: %s\n", to_string(parsed.errors.front()).c_str());
    return 2;
  }
  synbench::emulator::TwinBench bench(cfg);
  synbench::bench::SafetySupervisor supervisor(bench.devices(), synbench::bench::safety_limits(*parsed.plan));
  RecordSink sink;
  synbench::bench::SweepBench sweep_bench;
  sweep_bench.load_b1_Nms_per_rad = cfg.load.b1_Nms_per_rad;
  synbench::bench::SweepEngine engine(bench.devices(), supervisor, *parsed.plan, {}, sink, sweep_bench);

  const auto t0 = std::chrono::steady_clock::now();
  // As `synbench sweep` on the in-process twin: supervisor, then engine, every 10 ms.
  for (double t = 0; !engine.finished();) {
    t += 0.01;
    bench.clock().wait_until(t);
    supervisor.tick(t);
    engine.tick(t);
  }
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::map<double, Tally> by_speed;
  Tally all;
  for (const auto& r : sink.records) {
    for (Tally* x : {&by_speed[r.speed_rpm], &all}) {
      ++x->points;
      x->settle_sum_s += r.settle_s;
      x->unstable += r.unstable ? 1 : 0;
      // The drive's lock guard ran the point on the encoder: its error fields are the encoder's.
      x->lock_lost += r.lock_lost ? 1 : 0;
      // An EEMF's low-speed fallback gave the angle for part of the window (a hand-back).
      x->on_fallback += r.fallback_fraction > 0 ? 1 : 0;
      x->max_fallback = std::max(x->max_fallback, r.fallback_fraction);
      if (!r.pos_err_mean_deg || r.lock_lost) continue;
      const bool lost = *r.pos_err_max_deg - *r.pos_err_min_deg > 90.0;
      x->out_of_lock += lost ? 1 : 0;
      if (!lost) x->worst_in_lock_deg = std::max(x->worst_in_lock_deg, std::fabs(*r.pos_err_mean_deg));
    }
    if (verbose)
      std::printf("%g rpm %g N m %g deg: pos %+.2f [%+.1f, %+.1f] deg, speed %.1f rpm, "
                  "settle %.1f s, fallback %.1f %%%s\n",
                  r.speed_rpm, r.load_Nm, r.angle_deg, r.pos_err_mean_deg.value_or(NAN),
                  r.pos_err_min_deg.value_or(NAN), r.pos_err_max_deg.value_or(NAN),
                  r.speed_meas_rpm, r.settle_s, 100.0 * r.fallback_fraction,
                  r.unstable ? " UNSTABLE" : r.lock_lost ? " LOCK LOST" : "");
  }
  auto print = [](const char* what, const Tally& t) {
    std::printf("%-8s %4d points, %3d unstable, %3d lock lost, %3d out of lock, worst |mean| in "
                "lock %5.2f deg, mean settle %.1f s, %3d on the fallback (at most %.1f %%)\n",
                what, t.points, t.unstable, t.lock_lost, t.out_of_lock, t.worst_in_lock_deg,
                t.points ? t.settle_sum_s / t.points : 0.0, t.on_fallback,
                100.0 * t.max_fallback);
  };
  std::printf("%s / %s, as a sweep\n", std::string(synbench::drivers::name(e)).c_str(),
              std::string(synbench::drivers::name(*pwm)).c_str());
  for (const auto& [speed, t] : by_speed) {
    char what[32];
    std::snprintf(what, sizeof what, "%g rpm", speed);
    print(what, t);
  }
  print("all", all);
  std::printf("restarts after a lost speed: %d\n", sink.restarts);
  const bool completed = engine.state() == synbench::bench::SweepState::completed;
  std::printf("sweep %s after %zu of %zu points%s%s\n",
              std::string(synbench::bench::name(engine.state())).c_str(), sink.records.size(),
              engine.progress().total, completed ? "" : ": ", completed ? "" : engine.error().c_str());
  std::printf("wall %.1f s\n", wall_s);
  return completed ? 0 : 1;
}
