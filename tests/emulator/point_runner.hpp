// Test helper: one operating point on a fresh in-process twin, through the bench's procedure.
#pragma once

#include "bench/point_procedure.hpp"
#include "emulator/twin_bench.hpp"

namespace synbench::testing {

inline bench::PointRecord measure(const emulator::TwinConfig& config, double speed_rpm,
                                  double load_Nm, double angle_deg,
                                  drivers::Pwm pwm = drivers::Pwm::capwm, double window_s = 1.0) {
  emulator::TwinBench bench(config);
  bench::PointRequest req;
  req.speed_rpm = speed_rpm;
  req.load_Nm = load_Nm;
  req.angle_deg = angle_deg;
  req.pwm = pwm;
  req.window_s = window_s;
  bench::PointOptions opt;
  opt.load_b1_Nms_per_rad = config.load.b1_Nms_per_rad;
  opt.ordered_stop_after = false;
  auto proc = bench::run_point(bench.devices(), bench.clock(), req, opt);
  return proc.record();
}

}  // namespace synbench::testing
