// Test helper: one operating point on a fresh in-process twin, through the bench's procedure.
#pragma once

#include "bench/point_procedure.hpp"
#include "emulator/twin_bench.hpp"

namespace synbench::testing {

// The request on a fresh twin, without the ordered stop at the end.
inline bench::PointRecord measure(const emulator::TwinConfig& config, const bench::PointRequest& req,
                                  double settle_timeout_s = bench::PointOptions{}.settle_timeout_s) {
  emulator::TwinBench bench(config);
  bench::PointOptions opt;
  opt.load_b1_Nms_per_rad = config.load.b1_Nms_per_rad;
  opt.ordered_stop_after = false;
  opt.settle_timeout_s = settle_timeout_s;
  return bench::run_point(bench.devices(), bench.clock(), req, opt).record();
}

inline bench::PointRecord measure(const emulator::TwinConfig& config, double speed_rpm,
                                  double load_Nm, double angle_deg,
                                  drivers::Pwm pwm = drivers::Pwm::capwm, double window_s = 1.0) {
  bench::PointRequest req;
  req.speed_rpm = speed_rpm;
  req.load_Nm = load_Nm;
  req.angle_deg = angle_deg;
  req.pwm = pwm;
  req.window_s = window_s;
  return measure(config, req);
}

}  // namespace synbench::testing
