// The estimators' characterisation against the thesis's findings (physics.md Sec. 9) at five
// noise seeds, not one: a threshold that holds at the default seed and fails at another is a
// property of that noise draw, not of the estimator. A few points each, so the suite stays short
// (closed_loop_estimators_test.cpp covers the grid at the default seed).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "point_runner.hpp"

namespace synbench {
namespace {

constexpr int kSeeds[] = {1, 2, 3, 4, 5};

bench::PointRecord measure_at_seed(int seed, drivers::Estimator e, double speed, double load, double angle,
                                   drivers::Pwm pwm) {
  emulator::TwinConfig cfg;
  cfg.sim.seed_int = seed;
  bench::PointRequest req;
  req.speed_rpm = speed;
  req.load_Nm = load;
  req.angle_deg = angle;
  req.estimator = e;
  req.pwm = pwm;
  return testing::measure(cfg, req, 5.0);
}

std::string where(int seed, drivers::Estimator e, double speed, double load, double angle) {
  char buf[120];
  std::snprintf(buf, sizeof buf, "seed %d %s %.0f rpm %.1f N m %.0f deg", seed, std::string(drivers::name(e)).c_str(),
                speed, load, angle);
  return buf;
}

// EKF-BASIC and EKF-RS: steady-state position error within +/-7.5 deg from 100 rpm, Ld and Lq
// within +/-30 % (Sec. 6.3.2), at the corners of the grid.
TEST(EstimatorsOverSeeds, EkfsHoldTheThesisBoundsAtEverySeed) {
  struct P {
    double speed, load, angle;
  };
  for (const int seed : kSeeds)
    for (auto e : {drivers::Estimator::ekf_basic, drivers::Estimator::ekf_rs})
      for (const P p : {P{100, 2.0, 58}, P{900, 3.5, 76}, P{500, 0.5, 40}}) {
        const auto r = measure_at_seed(seed, e, p.speed, p.load, p.angle, drivers::Pwm::aspwm);
        const auto at = where(seed, e, p.speed, p.load, p.angle);
        ASSERT_FALSE(r.fault) << at;
        ASSERT_TRUE(r.pos_err_mean_deg && r.ld_err_pct && r.lq_err_pct) << at;
        std::printf("%s: pos %+5.2f deg, Ld %+5.1f %%, Lq %+5.1f %%\n", at.c_str(), *r.pos_err_mean_deg,
                    *r.ld_err_pct, *r.lq_err_pct);
        EXPECT_LE(std::fabs(*r.pos_err_mean_deg), 7.5) << at;
        EXPECT_LE(std::fabs(*r.ld_err_pct), 30.0) << at;
        EXPECT_LE(std::fabs(*r.lq_err_pct), 30.0) << at;
      }
}

// EEMF-RLS: a small mean position error but a large spread, and Rs errors of tens of percent
// (Sec. 6.3.2, Fig. 6.15), here as |mean| < 5 deg, spread > 10 deg, |Rs error| < 80 % at every
// point. "Tens of percent" is the thesis's histogram over all points (20 % bins), and is tested
// as such: the median |Rs error| over the seeds and angles above 10 %. Per point it is not a
// property of the estimator: at 40 deg the error ranged over -8.8 % (seed 2) to -27 % (seed 5)
// (2026-12-03). At 0.5 N m the Rs drop (~1.5 V) is small against the 20 V PRBS and the current
// noise, so the identified Rs moves with the noise draw.
TEST(EstimatorsOverSeeds, EemfRlsSmallMeanLargeSpreadAndRsOffByTensOfPercentAtEverySeed) {
  std::vector<double> rs_abs_pct;
  for (const int seed : kSeeds)
    for (const double angle : {40.0, 56.0}) {
      const auto e = drivers::Estimator::eemf_rls;
      const auto r = measure_at_seed(seed, e, 700, 0.5, angle, drivers::Pwm::capwm);
      const auto at = where(seed, e, 700, 0.5, angle);
      ASSERT_FALSE(r.fault) << at;
      ASSERT_FALSE(r.lock_lost) << at;
      ASSERT_TRUE(r.pos_err_mean_deg && r.pos_err_min_deg && r.pos_err_max_deg && r.rs_err_pct) << at;
      const double spread = *r.pos_err_max_deg - *r.pos_err_min_deg;
      std::printf("%s: mean %+5.2f deg, spread %5.1f deg, Rs %+5.1f %%\n", at.c_str(), *r.pos_err_mean_deg, spread,
                  *r.rs_err_pct);
      EXPECT_LT(std::fabs(*r.pos_err_mean_deg), 5.0) << at;
      EXPECT_GT(spread, 10.0) << at;
      EXPECT_LT(spread, 90.0) << at << ": out of lock";
      EXPECT_LT(std::fabs(*r.rs_err_pct), 80.0) << at;
      rs_abs_pct.push_back(std::fabs(*r.rs_err_pct));
    }
  std::sort(rs_abs_pct.begin(), rs_abs_pct.end());
  const double median = 0.5 * (rs_abs_pct[rs_abs_pct.size() / 2 - 1] + rs_abs_pct[rs_abs_pct.size() / 2]);
  std::printf("EEMF-RLS |Rs error| over seeds and angles: %.1f .. %.1f %%, median %.1f %%\n", rs_abs_pct.front(),
              rs_abs_pct.back(), median);
  EXPECT_GT(median, 10.0);
}

// HFI holds the low-speed range with a small mean error (Sec. 6.2.2).
TEST(EstimatorsOverSeeds, HfiHoldsTheLowSpeedRangeAtEverySeed) {
  for (const int seed : kSeeds)
    for (const double speed : {100.0, 300.0}) {
      const auto e = drivers::Estimator::hfi;
      const auto r = measure_at_seed(seed, e, speed, 2.0, 56, drivers::Pwm::capwm);
      const auto at = where(seed, e, speed, 2.0, 56);
      ASSERT_FALSE(r.fault) << at;
      ASSERT_TRUE(r.pos_err_mean_deg) << at;
      std::printf("%s: mean %+5.2f deg\n", at.c_str(), *r.pos_err_mean_deg);
      EXPECT_LT(std::fabs(*r.pos_err_mean_deg), 5.0) << at;
      EXPECT_NEAR(r.speed_meas_rpm, speed, 0.02 * speed) << at;
    }
}

}  // namespace
}  // namespace synbench
