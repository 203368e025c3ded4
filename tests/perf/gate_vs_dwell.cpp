// Benchmark: bench time per point with the steady-state gate against a fixed 5 s dwell, at the
// repeatability of P_dcM each achieves (issue "Sweep engine": report both and the ratio, target
// <= 0.4). Angle sweeps at three (speed, load) pairs, chained as a sweep runs them, repeated with
// five noise seeds; repeatability is the standard deviation of P_dcM over the seeds.
#include <cmath>
#include <cstdio>
#include <vector>

#include "bench/point_procedure.hpp"
#include "emulator/twin_bench.hpp"

using namespace synbench;

struct Result {
  double bench_s_per_point = 0;
  double pdcm_sd_W = 0;
};

Result run(bool gate) {
  const double pairs[][2] = {{300, 1.0}, {700, 2.5}, {900, 3.5}};
  const std::vector<double> angles = {46, 50, 54, 58, 62};
  const int seeds = 5;
  std::vector<std::vector<double>> pdcm(15);
  double bench_s = 0;
  int points = 0;
  for (int seed = 1; seed <= seeds; ++seed) {
    emulator::TwinConfig cfg;
    cfg.sim.seed_int = seed;
    emulator::TwinBench bench(cfg);
    bench::PointOptions opt;
    opt.ordered_stop_after = false;
    opt.continue_running = true;
    opt.load_b1_Nms_per_rad = cfg.load.b1_Nms_per_rad;
    if (!gate) {
      // A fixed dwell: wait 5 s after the load is applied, whatever the signals do.
      opt.min_settle_s = 5.0;
      opt.gate.speed_band_rpm = 1e9;
      opt.gate.im_band_min_A = 1e9;
      opt.gate.power_band_min_W = 1e9;
    }
    int k = 0;
    for (const auto& p : pairs)
      for (double a : angles) {
        bench::PointRequest req;
        req.speed_rpm = p[0];
        req.load_Nm = p[1];
        req.angle_deg = a;
        const double t0 = bench.clock().now_s();
        const auto proc = bench::run_point(bench.devices(), bench.clock(), req, opt);
        if (a != angles.front()) {  // the first of each pair includes the speed/load change
          bench_s += bench.clock().now_s() - t0;
          ++points;
        }
        pdcm[static_cast<std::size_t>(k++)].push_back(proc.record().pdcm_W);
      }
  }
  double var = 0;
  int n = 0;
  for (const auto& v : pdcm) {
    double m = 0;
    for (double x : v) m += x;
    m /= static_cast<double>(v.size());
    for (double x : v) var += (x - m) * (x - m) / static_cast<double>(v.size() - 1);
    ++n;
  }
  return {bench_s / points, std::sqrt(var / n)};
}

int main() {
  const Result g = run(true), d = run(false);
  std::printf("steady-state gate: %.2f s of bench time per point, P_dcM repeatability %.3f W (sd over 5 seeds)\n",
              g.bench_s_per_point, g.pdcm_sd_W);
  std::printf("fixed 5 s dwell:   %.2f s of bench time per point, P_dcM repeatability %.3f W\n",
              d.bench_s_per_point, d.pdcm_sd_W);
  std::printf("ratio gate / dwell: %.2f (target <= 0.4)\n", g.bench_s_per_point / d.bench_s_per_point);
  return 0;
}
