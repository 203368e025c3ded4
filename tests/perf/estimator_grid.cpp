// Benchmark: EKF-BASIC and EKF-RS over the full thesis grid (Sec. 6.3.2: 100..900 rpm step 200,
// 0.5..3.5 N m step 0.5, 40..76 deg step 2; 665 points each) on the twin, ASPWM, one fresh twin
// per point through the bench's point procedure. Issue "Sensorless estimators": |mean position
// error| <= 7.5 deg and Ld, Lq within +/-30 % at every point, from 100 rpm. Prints the worst
// figures (and every point with --verbose); exits 1 if a point faults or breaks a limit.
// usage: estimator_grid [--smoke] [--capwm] [--verbose] [--csv FILE]
//   --smoke: 2 speeds x 2 loads x 2 angles (the grid's corners), for ctest.
//   --capwm: centre-aligned PWM instead of the thesis' ASPWM (a user may pick it).
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "tests/emulator/point_runner.hpp"

namespace {

using synbench::drivers::Estimator;

constexpr double kPosLimitDeg = 7.5, kInductanceLimitPct = 30.0;

std::vector<double> range(double from, double to, double step) {
  std::vector<double> v;
  for (int k = 0; from + k * step <= to + 1e-9; ++k) v.push_back(from + k * step);
  return v;
}

struct Worst {
  double pos_deg = 0, ld_pct = 0, lq_pct = 0, rs_pct = 0;
  std::string pos_at, ld_at, lq_at, rs_at;
  int points = 0, faults = 0, violations = 0, unstable = 0;
};

void keep_worst(double v, double& worst, std::string& at, const std::string& here) {
  if (std::fabs(v) > std::fabs(worst)) {
    worst = v;
    at = here;
  }
}

}  // namespace

int main(int argc, char** argv) {
  bool smoke = false, verbose = false;
  auto pwm = synbench::drivers::Pwm::aspwm;
  const char* csv_path = nullptr;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--smoke")) smoke = true;
    else if (!std::strcmp(argv[i], "--verbose")) verbose = true;
    else if (!std::strcmp(argv[i], "--capwm")) pwm = synbench::drivers::Pwm::capwm;
    else if (!std::strcmp(argv[i], "--csv") && i + 1 < argc) csv_path = argv[++i];
    else {
      std::fprintf(stderr, "usage: %s [--smoke] [--capwm] [--verbose] [--csv FILE]\n", argv[0]);
      return 2;
    }
  }
  const auto speeds = smoke ? std::vector<double>{100, 900} : range(100, 900, 200);
  const auto loads = smoke ? std::vector<double>{0.5, 3.5} : range(0.5, 3.5, 0.5);
  const auto angles = smoke ? std::vector<double>{40, 76} : range(40, 76, 2);
  FILE* csv = csv_path ? std::fopen(csv_path, "w") : nullptr;
  if (csv)
    std::fprintf(csv, "estimator,speed_rpm,load_Nm,angle_deg,fault,unstable,pos_err_mean_deg,"
                      "pos_err_min_deg,pos_err_max_deg,ld_err_pct,lq_err_pct,rs_err_pct\n");

  bool ok = true;
  for (const Estimator e : {Estimator::ekf_basic, Estimator::ekf_rs}) {
    Worst w;
    const std::string name(synbench::drivers::name(e));
    for (double speed : speeds)
      for (double load : loads)
        for (double angle : angles) {
          const synbench::bench::PointRequest req{
              .speed_rpm = speed, .load_Nm = load, .angle_deg = angle, .estimator = e, .pwm = pwm};
          const auto r = synbench::testing::measure(synbench::emulator::TwinConfig{}, req, 5.0);
          char here[96];
          std::snprintf(here, sizeof here, "%g rpm %g N m %g deg", speed, load, angle);
          ++w.points;
          w.unstable += r.unstable ? 1 : 0;
          const bool complete = !r.fault && r.pos_err_mean_deg && r.ld_err_pct && r.lq_err_pct;
          if (!complete) {
            ++w.faults;
            std::printf("%s %s: %s\n", name.c_str(), here,
                        r.fault ? r.fault->c_str() : "no estimate");
          } else {
            const double pos = *r.pos_err_mean_deg, ld = *r.ld_err_pct, lq = *r.lq_err_pct;
            keep_worst(pos, w.pos_deg, w.pos_at, here);
            keep_worst(ld, w.ld_pct, w.ld_at, here);
            keep_worst(lq, w.lq_pct, w.lq_at, here);
            if (r.rs_err_pct) keep_worst(*r.rs_err_pct, w.rs_pct, w.rs_at, here);
            const bool bad = std::fabs(pos) > kPosLimitDeg || std::fabs(ld) > kInductanceLimitPct ||
                             std::fabs(lq) > kInductanceLimitPct;
            w.violations += bad ? 1 : 0;
            if (verbose || bad)
              std::printf("%s %s: pos %+.2f deg [%+.1f, %+.1f], Ld %+.1f %%, Lq %+.1f %%%s\n",
                          name.c_str(), here, pos, *r.pos_err_min_deg, *r.pos_err_max_deg, ld, lq,
                          bad ? "  LIMIT" : "");
          }
          if (csv) {
            auto opt = [](const std::optional<double>& v) {
              return v ? std::to_string(*v) : std::string();
            };
            std::fprintf(csv, "%s,%g,%g,%g,%s,%d,%s,%s,%s,%s,%s,%s\n", name.c_str(), speed, load,
                         angle, r.fault ? r.fault->c_str() : "", r.unstable ? 1 : 0,
                         opt(r.pos_err_mean_deg).c_str(), opt(r.pos_err_min_deg).c_str(),
                         opt(r.pos_err_max_deg).c_str(), opt(r.ld_err_pct).c_str(),
                         opt(r.lq_err_pct).c_str(), opt(r.rs_err_pct).c_str());
          }
        }
    std::printf("%s: %d points, %d faulted, %d over a limit, %d flagged unstable\n", name.c_str(),
                w.points, w.faults, w.violations, w.unstable);
    std::printf("  worst mean position error %+.2f deg (%s)\n", w.pos_deg, w.pos_at.c_str());
    std::printf("  worst Ld error %+.1f %% (%s)\n", w.ld_pct, w.ld_at.c_str());
    std::printf("  worst Lq error %+.1f %% (%s)\n", w.lq_pct, w.lq_at.c_str());
    if (e == Estimator::ekf_rs)
      std::printf("  worst Rs error %+.1f %% (%s)\n", w.rs_pct, w.rs_at.c_str());
    ok = ok && w.faults == 0 && w.violations == 0;
  }
  if (csv) std::fclose(csv);
  return ok ? 0 : 1;
}
