// Sensorless estimators closed loop on the twin: the estimator's angle drives the FOC, the
// encoder only measures the error (issue "Sensorless estimators", physics.md 8 and 9).
#include <gtest/gtest.h>

#include <cmath>

#include "point_runner.hpp"

namespace synbench {
namespace {

bench::PointRecord measure_with(drivers::Estimator e, double speed, double load, double angle,
                                drivers::Pwm pwm = drivers::Pwm::capwm) {
  emulator::TwinConfig cfg;
  emulator::TwinBench bench(cfg);
  bench::PointRequest req;
  req.speed_rpm = speed;
  req.load_Nm = load;
  req.angle_deg = angle;
  req.estimator = e;
  req.pwm = pwm;
  bench::PointOptions opt;
  opt.load_b1_Nms_per_rad = cfg.load.b1_Nms_per_rad;
  opt.ordered_stop_after = false;
  opt.settle_timeout_s = 5.0;
  return bench::run_point(bench.devices(), bench.clock(), req, opt).record();
}

TEST(ClosedLoopEstimators, HfiHoldsTheLowSpeedRangeAndCostsCurrentAndPower) {
  for (double speed : {100.0, 300.0}) {
    const auto enc = measure_with(drivers::Estimator::encoder, speed, 2.0, 56);
    const auto hfi = measure_with(drivers::Estimator::hfi, speed, 2.0, 56);
    ASSERT_TRUE(hfi.pos_err_mean_deg && hfi.pos_err_min_deg && hfi.pos_err_max_deg);
    EXPECT_FALSE(enc.pos_err_mean_deg) << "no estimator fields for the encoder";
    EXPECT_LT(std::fabs(*hfi.pos_err_mean_deg), 5.0) << speed;
    EXPECT_LT(*hfi.pos_err_max_deg - *hfi.pos_err_min_deg, 45.0) << speed;
    EXPECT_NEAR(hfi.speed_meas_rpm, speed, 0.02 * speed);
    EXPECT_NEAR(*hfi.speed_err_rpm, 0.0, 3.0);
    EXPECT_GT(hfi.im_A, enc.im_A) << speed;
    EXPECT_GT(hfi.pdcm_W, enc.pdcm_W) << speed;
  }
}

}  // namespace
}  // namespace synbench
