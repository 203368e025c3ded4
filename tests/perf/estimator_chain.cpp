// Benchmark: one sensorless configuration through the thesis grid chained as a sweep runs it
// (bench/sweep_engine: one twin, the drives kept running, speed > load > angle, the gate deciding
// when a point has settled). A fresh twin per point (estimator_grid) hides what a sweep meets:
// the observer must carry its lock through every setpoint change. Prints per-speed counts of
// faults, points flagged unstable and points out of lock (position-error span over 90 deg: a
// slipping observer sweeps the whole (-90, 90] deg), the worst |mean position error| in lock, the
// mean settling time and the wall time. Exits 1 when a point faults.
// usage: estimator_chain --estimator NAME [--pwm capwm|aspwm] [--speeds a,b,..] [--loads ..]
//                        [--angles ..] [--timeout-s S] [--config FILE] [--verbose]
//   defaults: the thesis grid (EEMF variants from 500 rpm), the thesis PWM of the estimator,
//   the gate timeout of bench::PointOptions.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <map>
#include <string>
#include <vector>

#include "bench/point_procedure.hpp"
#include "emulator/twin_bench.hpp"
#include "emulator/twin_config_schema.hpp"

namespace {

using synbench::drivers::Estimator;
using synbench::drivers::Pwm;

std::vector<double> range(double from, double to, double step) {
  std::vector<double> v;
  for (int k = 0; from + k * step <= to + 1e-9; ++k) v.push_back(from + k * step);
  return v;
}

std::vector<double> list(const char* s) {
  std::vector<double> v;
  for (char* end = nullptr; *s; s = (*end == ',') ? end + 1 : end) {
    v.push_back(std::strtod(s, &end));
    if (end == s) break;
  }
  return v;
}

struct Tally {
  int points = 0, faults = 0, unstable = 0, out_of_lock = 0, restarts = 0;
  double worst_in_lock_deg = 0, settle_sum_s = 0;
};

// What bench::SweepEngine does after a lost point: load torque to zero, then disable (the
// shaft coasts; a drive that lost the rotor is not asked to decelerate it).
void ordered_stop(synbench::emulator::TwinBench& bench) {
  auto dev = bench.devices();
  auto& clock = bench.clock();
  dev.load->set_torque_Nm(0.0);
  clock.wait_until(clock.now_s() + 1.0);
  dev.synrm->enable(false);
  dev.load->enable(false);
}

}  // namespace

int main(int argc, char** argv) {
  Estimator e = Estimator::encoder;  // encoder: none given (or a bad argument)
  std::optional<Pwm> pwm;
  std::vector<double> speeds, loads = range(0.5, 3.5, 0.5), angles = range(40, 76, 2);
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
  const bool eemf = e == Estimator::eemf_const || e == Estimator::eemf_lut || e == Estimator::eemf_rls;
  const bool ekf = e == Estimator::ekf_basic || e == Estimator::ekf_rs;
  if (speeds.empty()) speeds = eemf ? range(500, 900, 200) : range(100, 900, 200);
  if (!pwm) pwm = ekf ? Pwm::aspwm : Pwm::capwm;

  synbench::emulator::TwinConfig cfg;
  try {
    if (config_path) cfg = synbench::emulator::load_twin_config_file(config_path);
  } catch (const std::exception& ex) {
    std::fprintf(stderr, "%s\n", ex.what());
    return 2;
  }
  synbench::emulator::TwinBench bench(cfg);
  synbench::bench::PointOptions opt;
  opt.load_b1_Nms_per_rad = cfg.load.b1_Nms_per_rad;
  opt.ordered_stop_after = false;
  opt.continue_running = true;
  if (timeout_s) opt.settle_timeout_s = *timeout_s;

  const auto t0 = std::chrono::steady_clock::now();
  std::map<double, Tally> by_speed;
  Tally all;
  bool faulted = false;
  for (double speed : speeds) {
    for (double load : loads) {
      for (double angle : angles) {
        const synbench::bench::PointRequest req{
            .speed_rpm = speed, .load_Nm = load, .angle_deg = angle, .estimator = e, .pwm = *pwm};
        const auto proc = synbench::bench::run_point(bench.devices(), bench.clock(), req, opt);
        const auto& r = proc.record();
        // As the sweep engine does: a drive that lost the speed is stopped in order and the next
        // point starts from standstill.
        if (proc.speed_lost()) {
          ++all.restarts;
          ordered_stop(bench);
        }
        Tally& t = by_speed[speed];
        for (Tally* x : {&t, &all}) {
          ++x->points;
          x->settle_sum_s += r.settle_s;
          if (r.fault) {
            ++x->faults;
            continue;
          }
          x->unstable += r.unstable ? 1 : 0;
          if (!r.pos_err_mean_deg) continue;
          const bool lost = *r.pos_err_max_deg - *r.pos_err_min_deg > 90.0;
          x->out_of_lock += lost ? 1 : 0;
          if (!lost)
            x->worst_in_lock_deg = std::max(x->worst_in_lock_deg, std::fabs(*r.pos_err_mean_deg));
        }
        if (verbose || r.fault)
          std::printf("%g rpm %g N m %g deg: %s pos %+.2f [%+.1f, %+.1f] deg, speed %.1f rpm, "
                      "settle %.1f s%s\n",
                      speed, load, angle, r.fault ? r.fault->c_str() : "ok",
                      r.pos_err_mean_deg.value_or(NAN), r.pos_err_min_deg.value_or(NAN),
                      r.pos_err_max_deg.value_or(NAN), r.speed_meas_rpm, r.settle_s,
                      r.unstable ? " UNSTABLE" : "");
        if (r.fault) {
          faulted = true;
          break;
        }
      }
      if (faulted) break;
    }
    if (faulted) break;
  }
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  auto print = [](const char* what, const Tally& t) {
    std::printf("%-8s %4d points, %d faulted, %3d unstable, %3d out of lock, worst |mean| in lock "
                "%5.2f deg, mean settle %.1f s\n",
                what, t.points, t.faults, t.unstable, t.out_of_lock, t.worst_in_lock_deg,
                t.points ? t.settle_sum_s / t.points : 0.0);
  };
  std::printf("%s / %s, chained\n", std::string(synbench::drivers::name(e)).c_str(),
              std::string(synbench::drivers::name(*pwm)).c_str());
  for (const auto& [speed, t] : by_speed) {
    char what[32];
    std::snprintf(what, sizeof what, "%g rpm", speed);
    print(what, t);
  }
  print("all", all);
  std::printf("restarts after a lost speed: %d\n", all.restarts);
  std::printf("wall %.1f s\n", wall_s);
  return faulted ? 1 : 0;
}
