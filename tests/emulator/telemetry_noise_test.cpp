// The noise of the twin's running telemetry, the measurement behind the frozen-telemetry check's
// noise floors (drivers/frozen_watch.hpp): at steady operating points, read as the bench reads
// (every 50 ms, a profile's poll period) for 5 s, each watched signal's standard deviation must
// stay well above its floor (the floors keep a margin of 3), else a value whose register steps are finer than the floor could still
// sit bit for bit still while the drive runs and the check would trip on a healthy drive.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "bench/point_procedure.hpp"
#include "drivers/frozen_watch.hpp"
#include "emulator/twin_bench.hpp"

namespace synbench {
namespace {

struct OperatingPoint {
  double speed_rpm, load_Nm, angle_deg;
};

// Standard deviation of each watched signal over `reads` reads `period_s` apart, the drive
// steady at `op` (ordered stop left out: the drive keeps running).
std::vector<double> telemetry_sigma(const OperatingPoint& op, int reads = 100, double period_s = 0.05) {
  const emulator::TwinConfig cfg;
  emulator::TwinBench bench(cfg);
  bench::PointRequest req;
  req.speed_rpm = op.speed_rpm;
  req.load_Nm = op.load_Nm;
  req.angle_deg = op.angle_deg;
  req.window_s = 0.1;
  bench::PointOptions opt;
  opt.ordered_stop_after = false;
  opt.load_b1_Nms_per_rad = cfg.load.b1_Nms_per_rad;
  const auto p = bench::run_point(bench.devices(), bench.clock(), req, opt);
  EXPECT_TRUE(p.has_record()) << p.error();
  const auto& watched = drivers::kFrozenWatched;
  std::vector<double> sum(watched.size()), sum2(watched.size());
  double t = bench.clock().now_s();
  for (int k = 0; k < reads; ++k) {
    t += period_s;
    bench.clock().wait_until(t);
    drivers::SynrmTelemetry tel;
    EXPECT_FALSE(bench.devices().synrm->read(tel));
    EXPECT_TRUE(drivers::running(tel.state));
    for (std::size_t i = 0; i < watched.size(); ++i) {
      const double v = tel.*watched[i].value;
      sum[i] += v;
      sum2[i] += v * v;
    }
  }
  std::vector<double> sigma(watched.size());
  for (std::size_t i = 0; i < watched.size(); ++i) {
    const double mean = sum[i] / reads;
    sigma[i] = std::sqrt(std::max(0.0, sum2[i] / reads - mean * mean));
  }
  return sigma;
}

TEST(TelemetryNoise, TwinRunsNoisierThanTheFrozenCheckFloors) {
  // Unloaded low speed, a mid point, rated load at top speed: the floors hold at the quietest.
  for (const OperatingPoint op : {OperatingPoint{300, 0.0, 45}, OperatingPoint{1000, 2.0, 60},
                                  OperatingPoint{1500, 3.5, 55}}) {
    const auto sigma = telemetry_sigma(op);
    for (std::size_t i = 0; i < sigma.size(); ++i) {
      const auto& w = drivers::kFrozenWatched[i];
      std::printf("%4g rpm %3g N m %2g deg: %-9s sigma %.3g %s (floor %.3g)\n", op.speed_rpm, op.load_Nm,
                  op.angle_deg, w.name, sigma[i], w.unit, drivers::kRunningNoise.*w.noise);
      // The floors sit a factor 3 below the quietest point; 2.5 of it must remain.
      EXPECT_GE(sigma[i], 2.5 * (drivers::kRunningNoise.*w.noise))
          << w.name << " at " << op.speed_rpm << " rpm, " << op.load_Nm << " N m";
    }
  }
}

}  // namespace
}  // namespace synbench
