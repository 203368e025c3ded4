// Sensorless estimators closed loop on the twin: the estimator's angle drives the FOC, the
// encoder only measures the error (issue "Sensorless estimators", physics.md 8 and 9).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <string>

#include "point_runner.hpp"

namespace synbench {
namespace {

bench::PointRecord measure_with(drivers::Estimator e, double speed, double load, double angle,
                                drivers::Pwm pwm = drivers::Pwm::capwm) {
  bench::PointRequest req;
  req.speed_rpm = speed;
  req.load_Nm = load;
  req.angle_deg = angle;
  req.estimator = e;
  req.pwm = pwm;
  return testing::measure(emulator::TwinConfig{}, req, 5.0);
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

namespace synbench {
namespace {

// Issue "Sensorless estimators": over the grid (a subsample here; tests/perf runs the full one),
// EKF-BASIC and EKF-RS hold |mean position error| <= 7.5 deg and Ld, Lq within 30 %, from 100 rpm.
TEST(ClosedLoopEstimators, EkfsHoldPositionAndInductancesOverTheGrid) {
  for (auto e : {drivers::Estimator::ekf_basic, drivers::Estimator::ekf_rs})
    for (double speed : {100.0, 500.0, 900.0})
      for (double load : {0.5, 2.0, 3.5})
        for (double angle : {40.0, 58.0, 76.0}) {
          const auto r = measure_with(e, speed, load, angle, drivers::Pwm::aspwm);
          const std::string at = std::string(drivers::name(e)) + " " + std::to_string(speed) + " rpm " +
                                 std::to_string(load) + " N m " + std::to_string(angle) + " deg";
          ASSERT_FALSE(r.fault) << at;
          ASSERT_TRUE(r.pos_err_mean_deg && r.ld_err_pct && r.lq_err_pct) << at;
          EXPECT_LE(std::fabs(*r.pos_err_mean_deg), 7.5) << at;
          EXPECT_LE(std::fabs(*r.ld_err_pct), 30.0) << at;
          EXPECT_LE(std::fabs(*r.lq_err_pct), 30.0) << at;
          EXPECT_NEAR(r.speed_meas_rpm, speed, 0.01 * speed) << at;
          EXPECT_EQ(r.rs_est_ohm.has_value(), e == drivers::Estimator::ekf_rs) << at;
        }
}

// An EKF picked with CAPWM (the dashboard allows it): centre-aligned SVM near 50 % duty leaves
// no active vector long enough for the MCIDC slope, and the EKFs ran blind from standstill and
// tripped on over-current at every speed. With the modulator's window shift they hold the points.
TEST(ClosedLoopEstimators, EkfsHoldPointsWithCapwm) {
  for (auto e : {drivers::Estimator::ekf_basic, drivers::Estimator::ekf_rs})
    for (double speed : {100.0, 500.0, 900.0}) {
      const auto r = measure_with(e, speed, 1.0, 50.0, drivers::Pwm::capwm);
      const std::string at = std::string(drivers::name(e)) + " " + std::to_string(speed) + " rpm";
      ASSERT_FALSE(r.fault) << at;
      ASSERT_TRUE(r.pos_err_mean_deg) << at;
      EXPECT_LE(std::fabs(*r.pos_err_mean_deg), 7.5) << at;
      EXPECT_NEAR(r.speed_meas_rpm, speed, 0.01 * speed) << at;
      std::printf("%s CAPWM: pos err mean %+.3f deg\n", at.c_str(), *r.pos_err_mean_deg);
    }
}

struct PositionErrors {
  double mean_abs_in_lock_deg = 0;  // mean |mean position error| over the points in lock
  int in_lock = 0, points = 0;
};

// 700 rpm over the loads at three current angles, a fresh twin per point: the constant
// parameters' error changes sign with the angle (q-axis saturation), so one angle alone can hide
// it. A point out of lock (the error spans the whole (-90, 90] deg as the observer slips, or the
// lock guard took over) has a mean that says nothing; it is counted, not averaged.
PositionErrors position_errors_700(drivers::Estimator e, const emulator::TwinConfig& cfg) {
  PositionErrors out;
  double sum = 0;
  for (double angle : {40.0, 58.0, 76.0})
    for (double load : {0.5, 1.5, 2.5, 3.5}) {
      emulator::TwinBench bench(cfg);
      bench::PointRequest req;
      req.speed_rpm = 700;
      req.load_Nm = load;
      req.angle_deg = angle;
      req.estimator = e;
      // The thesis configurations: the EKFs with ASPWM, the EEMF family with CAPWM (physics.md 8).
      req.pwm = (e == drivers::Estimator::ekf_basic || e == drivers::Estimator::ekf_rs)
                    ? drivers::Pwm::aspwm
                    : drivers::Pwm::capwm;
      bench::PointOptions opt;
      opt.ordered_stop_after = false;
      opt.settle_timeout_s = 5.0;
      const auto r = bench::run_point(bench.devices(), bench.clock(), req, opt).record();
      ++out.points;
      EXPECT_FALSE(r.fault) << drivers::name(e) << " " << load << " N m " << angle << " deg";
      if (r.fault || !r.pos_err_mean_deg) continue;
      // The drive's lock guard ran the point on the encoder: the errors are the encoder's.
      if (r.lock_lost || *r.pos_err_max_deg - *r.pos_err_min_deg > 90.0) continue;
      sum += std::fabs(*r.pos_err_mean_deg);
      ++out.in_lock;
    }
  out.mean_abs_in_lock_deg = out.in_lock ? sum / out.in_lock : 0.0;
  return out;
}

// At 700 rpm: EEMF-CONST has the largest mean |position error| over the loads; EEMF-LUT with
// exact tables is better, and worse again with a deformed table: Lq x 1.25 (thesis 4.2) and
// Ld x 1.25 (4.1), "about 10 deg when Ld is 25 % off" (physics.md 9). A wrong Ld only multiplies
// p i in the EEMF's direction (physics.md 8): it is the magnitude the vector error reads
// against the tables (emf_angle_error.hpp) that it moves, so with the direction alone (the
// thesis' observer) it does not.
TEST(ClosedLoopEstimators, EemfConstErrsMostAndExactTablesHelp) {
  emulator::TwinConfig cfg;
  const auto konst = position_errors_700(drivers::Estimator::eemf_const, cfg);
  const auto lut = position_errors_700(drivers::Estimator::eemf_lut, cfg);
  const auto ekf = position_errors_700(drivers::Estimator::ekf_basic, cfg);
  cfg.estimators.eemf.lut_lq_scale = 1.25;
  const auto lut_lq = position_errors_700(drivers::Estimator::eemf_lut, cfg);
  cfg.estimators.eemf.lut_lq_scale = 1.0;
  cfg.estimators.eemf.lut_ld_scale = 1.25;
  const auto lut_ld = position_errors_700(drivers::Estimator::eemf_lut, cfg);
  cfg.estimators.eemf.error_signal = emulator::EemfErrorSignal::direction;
  const auto lut_ld_direction = position_errors_700(drivers::Estimator::eemf_lut, cfg);
  for (const auto& [name, r] : {std::pair{"EEMF-CONST", konst}, std::pair{"EEMF-LUT", lut},
                                std::pair{"EKF-BASIC", ekf}, std::pair{"EEMF-LUT Lq x1.25", lut_lq},
                                std::pair{"EEMF-LUT Ld x1.25", lut_ld},
                                std::pair{"Ld x1.25 direction", lut_ld_direction}})
    std::printf("700 rpm %-18s mean |pos err| in lock %5.2f deg, in lock at %2d of %d points\n", name,
                r.mean_abs_in_lock_deg, r.in_lock, r.points);
  EXPECT_EQ(ekf.in_lock, ekf.points);
  // Spun up and loaded at 45 deg before the point's own angle (PointOptions), EEMF-CONST holds
  // every point here (7 of 12 when each spun up at its own angle), EEMF-LUT too.
  EXPECT_GE(konst.in_lock, 11);
  EXPECT_EQ(lut.in_lock, lut.points);
  // Enough points in lock for the means to say something.
  for (const auto& r : {lut_lq, lut_ld, lut_ld_direction}) EXPECT_GE(r.in_lock, 6);
  EXPECT_GT(konst.mean_abs_in_lock_deg, lut.mean_abs_in_lock_deg + 2.0);
  EXPECT_GT(konst.mean_abs_in_lock_deg, ekf.mean_abs_in_lock_deg);
  EXPECT_LT(lut.mean_abs_in_lock_deg, 1.0);
  EXPECT_GT(lut_lq.mean_abs_in_lock_deg, lut.mean_abs_in_lock_deg + 2.0);
  EXPECT_GT(lut_ld.mean_abs_in_lock_deg, 5.0);
  EXPECT_LT(lut_ld.mean_abs_in_lock_deg, 15.0);
  EXPECT_LT(lut_ld_direction.mean_abs_in_lock_deg, 1.0);
}

// Points chained as a sweep runs them: the drives keep running between points.
bench::PointOptions chained_options(const emulator::TwinConfig& cfg) {
  bench::PointOptions opt;
  opt.load_b1_Nms_per_rad = cfg.load.b1_Nms_per_rad;
  opt.ordered_stop_after = false;
  opt.continue_running = true;
  opt.settle_timeout_s = 5.0;
  return opt;
}

struct ChainedLock {
  int lost = 0, points = 0;
  double worst_abs_in_lock_deg = 0;
};

// EEMF-LUT at 700 rpm as a sweep runs it (the drive kept running): each load through the given
// current angles, where the shaft makes an angle error grow (shaft_stiffness.hpp).
ChainedLock chained_lut_700(const emulator::TwinConfig& cfg, std::initializer_list<double> loads,
                            std::initializer_list<double> angles) {
  emulator::TwinBench bench(cfg);
  const auto opt = chained_options(cfg);
  ChainedLock out;
  for (double load : loads)
    for (double angle : angles) {
      bench::PointRequest req;
      req.speed_rpm = 700;
      req.load_Nm = load;
      req.angle_deg = angle;
      req.estimator = drivers::Estimator::eemf_lut;
      req.pwm = drivers::Pwm::capwm;
      const auto r = bench::run_point(bench.devices(), bench.clock(), req, opt).record();
      const std::string at = std::to_string(load) + " N m " + std::to_string(angle) + " deg";
      EXPECT_FALSE(r.fault) << at;
      ++out.points;
      if (r.lock_lost) {
        ++out.lost;
        continue;
      }
      if (r.pos_err_mean_deg)
        out.worst_abs_in_lock_deg = std::max(out.worst_abs_in_lock_deg, std::fabs(*r.pos_err_mean_deg));
    }
  return out;
}

// The thesis' observer, the EEMF's direction alone (`estimators.eemf.error_signal`
// "direction"), where the next two tests and docs/estimators.md ("What still fails") trace why
// it loses the rotor above the MTPA angle.
emulator::TwinConfig direction_only() {
  emulator::TwinConfig cfg;
  cfg.estimators.eemf.error_signal = emulator::EemfErrorSignal::direction;
  return cfg;
}

// On the direction alone a wrong Ld does not move the steady state (physics.md 8) but where the
// observer holds at all. The EEMF takes p i in a frame turning at its own speed estimate; an
// error dw of that estimate adds dw (Ld - Lq) J i to e, read as an angle error c dw with
// c = i_q (Ld - Lq) / |e|. That feeds the speed error the shaft makes (above the MTPA angle)
// back into the observer, and a larger Ld in the model makes c larger: the lock ends at lower
// current angles. The active-flux speed takes that term away (next test), the vector error the
// loss itself (the test after).
ChainedLock chained_lut_700_ld(double ld_scale) {
  emulator::TwinConfig cfg = direction_only();
  cfg.estimators.eemf.lut_ld_scale = ld_scale;
  return chained_lut_700(cfg, {1.0, 1.5, 2.0, 2.5, 3.0, 3.5}, {52.0, 56.0, 58.0, 60.0, 62.0});
}

TEST(ClosedLoopEstimators, EemfLutOnTheDirectionWithLdTimes125LosesLockAtLowerCurrentAngles) {
  const auto exact = chained_lut_700_ld(1.0);
  const auto ld = chained_lut_700_ld(1.25);
  std::printf("700 rpm chained EEMF-LUT, direction only: exact tables lose lock at %d of %d points "
              "(worst |mean| in lock %.2f deg), Ld x1.25 at %d (%.2f deg)\n",
              exact.lost, exact.points, exact.worst_abs_in_lock_deg, ld.lost, ld.worst_abs_in_lock_deg);
  EXPECT_LE(exact.lost, 6);
  EXPECT_GE(ld.lost, exact.lost + 6);
  // Where both hold, the steady state is the same: Ld does not move the direction.
  EXPECT_LT(exact.worst_abs_in_lock_deg, 1.0);
  EXPECT_LT(ld.worst_abs_in_lock_deg, 1.0);
}

// The active-flux rotor speed [ours] (`estimators.eemf.lut_rotation_speed`,
// active_flux_speed.hpp): the observer's own speed puts its error back into its reading as
// c dw; a speed from the active flux does not, so the direction-only lock reaches higher
// current angles (at 700 rpm in the thesis sweep it ends 6 to 10 deg higher; docs/estimators.md).
TEST(ClosedLoopEstimators, EemfLutOnTheActiveFluxSpeedHoldsLockToHigherCurrentAngles) {
  emulator::TwinConfig flux = direction_only();
  flux.estimators.eemf.lut_rotation_speed = emulator::LutRotationSpeed::active_flux;
  const auto thesis = chained_lut_700(direction_only(), {1.0, 2.0, 3.0}, {62.0, 64.0, 66.0, 68.0});
  const auto active = chained_lut_700(flux, {1.0, 2.0, 3.0}, {62.0, 64.0, 66.0, 68.0});
  std::printf("700 rpm chained EEMF-LUT at 62..68 deg, direction only: lock lost at %d of %d points "
              "on the observer's speed, at %d on the active flux's (worst |mean| in lock %.2f deg)\n",
              thesis.lost, thesis.points, active.lost, active.worst_abs_in_lock_deg);
  EXPECT_GE(thesis.lost, 6);
  EXPECT_LE(active.lost, 1);
  EXPECT_LT(active.worst_abs_in_lock_deg, 1.0);
}

// The vector error (the default, emf_angle_error.hpp) reads the EEMF's collapse itself when the
// estimate runs ahead above the MTPA angle: EEMF-LUT holds the thesis' highest current angles at
// every load, chained as a sweep runs them, where the direction alone loses most of them.
TEST(ClosedLoopEstimators, EemfLutOnTheWholeEmfVectorHoldsTheHighestCurrentAngles) {
  const auto vector = chained_lut_700(emulator::TwinConfig{}, {0.5, 2.0, 3.5}, {60.0, 66.0, 70.0, 76.0});
  const auto direction = chained_lut_700(direction_only(), {0.5, 2.0, 3.5}, {60.0, 66.0, 70.0, 76.0});
  std::printf("700 rpm chained EEMF-LUT at 60..76 deg: lock lost at %d of %d points on the vector "
              "error (worst |mean| in lock %.2f deg), at %d on the direction alone\n",
              vector.lost, vector.points, vector.worst_abs_in_lock_deg, direction.lost);
  EXPECT_EQ(vector.lost, 0);
  EXPECT_LT(vector.worst_abs_in_lock_deg, 1.0);
  EXPECT_GE(direction.lost, 6);
}

// EEMF-RLS, the thesis' shape (physics.md 9, Sec. 6.3.2 and 6.3.3) at 700 rpm and light load: a
// small mean position error but a wide spread, from the PRBS, far wider than EEMF-LUT's at the
// same point; Rs off by tens of percent; and the injection costs current and input power on the
// optimal trajectories: the minimum I_m (MTPA) and the minimum P_dcM (ME) over the current
// angles, against the encoder's. (Compared at one commanded angle, the RLS' few degrees of
// error move the current along the angle curve by as much as the PRBS adds.) Both minima are
// taken over the angles where the RLS held the rotor, and the encoder's must lie inside them.
TEST(ClosedLoopEstimators, EemfRlsSpreadsWithTheAngleAndThePrbsCostsCurrentAndPower) {
  double im_enc = 1e9, im_rls = 1e9, p_enc = 1e9, p_rls = 1e9, mtpa_deg = 0, held_to_deg = 0;
  for (double angle = 40.0; angle <= 76.0; angle += 2.0) {
    const auto rls = measure_with(drivers::Estimator::eemf_rls, 700, 0.5, angle);
    const std::string at = std::to_string(angle) + " deg";
    ASSERT_FALSE(rls.fault) << at;
    if (rls.lock_lost || std::fabs(rls.speed_meas_rpm - 700.0) > 14.0) break;
    held_to_deg = angle;
    ASSERT_TRUE(rls.pos_err_mean_deg && rls.pos_err_min_deg && rls.pos_err_max_deg && rls.rs_err_pct) << at;
    const auto enc = measure_with(drivers::Estimator::encoder, 700, 0.5, angle);
    if (enc.im_A < im_enc) mtpa_deg = angle;
    im_enc = std::min(im_enc, enc.im_A);
    im_rls = std::min(im_rls, rls.im_A);
    p_enc = std::min(p_enc, enc.pdcm_W);
    p_rls = std::min(p_rls, rls.pdcm_W);
    if (angle != 40.0 && angle != 48.0 && angle != 56.0) continue;
    const auto lut = measure_with(drivers::Estimator::eemf_lut, 700, 0.5, angle);
    ASSERT_TRUE(lut.pos_err_min_deg && lut.pos_err_max_deg) << at;
    const double spread = *rls.pos_err_max_deg - *rls.pos_err_min_deg;
    std::printf("700 rpm 0.5 N m %2.0f deg EEMF-RLS mean %+5.2f deg spread %5.1f deg (LUT %4.1f), "
                "Rs %+5.1f %%\n",
                angle, *rls.pos_err_mean_deg, spread, *lut.pos_err_max_deg - *lut.pos_err_min_deg,
                *rls.rs_err_pct);
    EXPECT_LT(std::fabs(*rls.pos_err_mean_deg), 5.0) << at;
    EXPECT_LT(spread, 90.0) << at << ": out of lock";
    EXPECT_GT(spread, 10.0) << at;
    EXPECT_GT(spread, 10.0 * (*lut.pos_err_max_deg - *lut.pos_err_min_deg)) << at;
    // At the default seed only: per point this bound is a noise draw's (-8.8 % at 40 deg with
    // seed 2); estimators_over_seeds_test.cpp tests the thesis's "tens of percent" over seeds.
    EXPECT_GT(std::fabs(*rls.rs_err_pct), 10.0) << at;
    EXPECT_LT(std::fabs(*rls.rs_err_pct), 80.0) << at;
  }
  std::printf("700 rpm 0.5 N m over 40..%.0f deg (RLS in lock): min I_m %.4f A (encoder %.4f A at "
              "%.0f deg, %+.1f %%), min P_dcM %.2f W (encoder %.2f W, %+.2f W)\n",
              held_to_deg, im_rls, im_enc, mtpa_deg, 100.0 * (im_rls / im_enc - 1.0), p_rls, p_enc,
              p_rls - p_enc);
  ASSERT_GE(held_to_deg, 56.0);
  EXPECT_LT(mtpa_deg, held_to_deg) << "the MTPA angle lies beyond the RLS' lock";
  EXPECT_GT(im_rls, im_enc);
  EXPECT_GT(p_rls, p_enc + 1.0);
}

}  // namespace
}  // namespace synbench

namespace synbench {
namespace {

// Sweep-like chaining (bench/sweep_engine: the drive keeps running, speed, load and current
// angle change together between points): EEMF-CONST and EEMF-LUT hold their angle through
// 3 loads x 5 angles at 700 rpm without a fault. (The observers still lose lock above about
// 55..60 deg at light load, where the EEMF is small: docs/estimators.md; HFI and EEMF-RLS are
// not covered yet.)
TEST(ClosedLoopEstimators, EemfHoldsAChainedSequenceOfPoints) {
  struct Case {
    drivers::Estimator e;
    double bound_deg;
  };
  for (const Case c : {Case{drivers::Estimator::eemf_const, 15.0}, Case{drivers::Estimator::eemf_lut, 6.0}}) {
    emulator::TwinConfig cfg;
    emulator::TwinBench bench(cfg);
    const auto opt = chained_options(cfg);
    for (double load : {0.5, 2.0, 3.5})
      for (double angle : {40.0, 45.0, 50.0, 55.0, 60.0}) {
        bench::PointRequest req;
        req.speed_rpm = 700;
        req.load_Nm = load;
        req.angle_deg = angle;
        req.estimator = c.e;
        req.pwm = drivers::Pwm::capwm;
        const auto r = bench::run_point(bench.devices(), bench.clock(), req, opt).record();
        const std::string at = std::string(drivers::name(c.e)) + " " + std::to_string(load) + " N m " +
                               std::to_string(angle) + " deg";
        ASSERT_FALSE(r.fault) << at;
        ASSERT_TRUE(r.pos_err_mean_deg) << at;
        EXPECT_LE(std::fabs(*r.pos_err_mean_deg), c.bound_deg) << at;
      }
  }
}

}  // namespace
}  // namespace synbench

namespace synbench {
namespace {

// The chained step that tripped HFI in the thesis sweep at 100 rpm: load up and current angle
// from 76 down to 40 deg at once, the drive kept running. Needs the PLL bandwidth raised where
// the shaft makes the angle error grow (above the MTPA angle at high load, shaft_stiffness.hpp)
// and the wide band-pass (its 13 ms envelope lag at 25 Hz sat inside the PLL).
TEST(ClosedLoopEstimators, HfiHoldsChainedLoadAndAngleSteps) {
  emulator::TwinConfig cfg;
  emulator::TwinBench bench(cfg);
  bench::PointOptions opt;
  opt.load_b1_Nms_per_rad = cfg.load.b1_Nms_per_rad;
  opt.ordered_stop_after = false;
  opt.continue_running = true;
  opt.settle_timeout_s = 5.0;
  struct Step {
    double load_Nm, angle_deg;
  };
  for (const Step s : {Step{1.5, 60}, Step{1.5, 76}, Step{2.0, 40}, Step{3.0, 76}, Step{3.5, 40},
                       Step{3.5, 76}}) {
    bench::PointRequest req;
    req.speed_rpm = 100;
    req.load_Nm = s.load_Nm;
    req.angle_deg = s.angle_deg;
    req.estimator = drivers::Estimator::hfi;
    req.pwm = drivers::Pwm::capwm;
    const auto r = bench::run_point(bench.devices(), bench.clock(), req, opt).record();
    const std::string at =
        std::to_string(s.load_Nm) + " N m " + std::to_string(s.angle_deg) + " deg";
    ASSERT_FALSE(r.fault) << at;
    ASSERT_TRUE(r.pos_err_mean_deg && r.pos_err_min_deg && r.pos_err_max_deg) << at;
    EXPECT_LT(std::fabs(*r.pos_err_mean_deg), 5.0) << at;
    // In lock: a slipping observer spans the whole (-90, 90] deg.
    EXPECT_LT(*r.pos_err_max_deg - *r.pos_err_min_deg, 90.0) << at;
    EXPECT_NEAR(r.speed_meas_rpm, 100.0, 5.0) << at;
  }
}

}  // namespace
}  // namespace synbench

namespace synbench {
namespace {

// After a lost point the drive's lock guard hands the rotor back to a fresh estimator once the
// next point's setpoints are reached, not when they are written: written, the current was still
// at the lost point's 76 deg, where the shaft makes any angle error grow, and the fresh EEMF-LUT
// lost the rotor again at the next 40 deg point of every load in the thesis sweep.
void run_s(emulator::Twin& tw, double s) {
  tw.run_steps(std::lround(s / tw.step_s()));
}

// Spun up at 45 deg on `e`, loaded at 2 N m/s as the bench ramps it, then driven to 76 deg, where
// the shaft makes any angle error grow, until the lock guard trips (an assertion failure if it
// does not, or if the 45 deg point did not hold); 0.5 s later, on the encoder.
void lose_the_rotor_at_76_deg(emulator::Twin& tw, drivers::Estimator e, double speed_rpm,
                              double load_Nm) {
  auto& d = tw.synrm_drive();
  ASSERT_FALSE(d.set_pwm(drivers::Pwm::capwm));
  ASSERT_FALSE(d.set_estimator(e));
  ASSERT_FALSE(d.set_angle_deg(45));
  ASSERT_FALSE(d.set_speed_rpm(speed_rpm));
  ASSERT_FALSE(d.enable(true));
  ASSERT_FALSE(tw.load_drive().enable(true));
  run_s(tw, 1.5);
  const int steps = static_cast<int>(std::ceil(load_Nm / 0.2 - 1e-9));
  for (int i = 1; i <= steps; ++i) {
    ASSERT_FALSE(tw.load_drive().set_torque_Nm(load_Nm * i / steps));
    run_s(tw, 0.1);
  }
  run_s(tw, 1.0);
  ASSERT_FALSE(d.telemetry().lock_lost) << "in lock at 45 deg";
  ASSERT_FALSE(d.set_angle_deg(76));
  bool lost = false;
  for (int i = 0; i < 500 && !lost; ++i) {
    run_s(tw, 0.01);
    lost = d.telemetry().lock_lost;
  }
  ASSERT_TRUE(lost) << drivers::name(e) << " holds " << speed_rpm << " rpm, " << load_Nm
                    << " N m, 76 deg: the test needs a lost point";
  run_s(tw, 0.5);
}

TEST(ClosedLoopEstimators, AnEemfPointWhollyOnItsEncoderFallbackHasNoPositionError) {
  // 300 rpm is below the EEMF's 500 rpm minimum: the encoder gives the angle all window long.
  // Its exact zeros are no measurement of the estimator (they pulled the means of points handed
  // back for part of their window toward zero); the RLS goes on identifying meanwhile.
  const auto r = measure_with(drivers::Estimator::eemf_rls, 300, 1.0, 50);
  EXPECT_FALSE(r.fault);
  EXPECT_EQ(r.fallback_fraction, 1.0);
  EXPECT_TRUE(r.below_min_speed);
  EXPECT_FALSE(r.pos_err_mean_deg || r.pos_err_min_deg || r.pos_err_max_deg || r.speed_err_rpm);
  ASSERT_TRUE(r.ld_est_H && r.lq_est_H && r.rs_est_ohm) << "the RLS's estimates are kept";
  EXPECT_GT(*r.ld_est_H, *r.lq_est_H) << "identified on the encoder's frame";
}

TEST(ClosedLoopEstimators, TheLockGuardHandsBackOnceTheNewSetpointsAreReached) {
  // The thesis' direction-only observer, which loses EEMF-LUT's rotor at 76 deg.
  emulator::TwinConfig cfg;
  cfg.estimators.eemf.error_signal = emulator::EemfErrorSignal::direction;
  emulator::Twin tw{cfg};
  auto& d = tw.synrm_drive();
  ASSERT_NO_FATAL_FAILURE(lose_the_rotor_at_76_deg(tw, drivers::Estimator::eemf_lut, 500, 2.0));
  // A window wholly on the guard has no estimator fields: its angle is the encoder's (an error
  // of exactly 0, which a record would show as a perfect estimate).
  EXPECT_FALSE(d.telemetry().pos_err_deg) << "the guard's angle is the encoder's";
  d.begin_window(2000);
  run_s(tw, 0.25);
  const auto w = d.window_result();
  EXPECT_EQ(w.lock_lost_fraction, 1.0);
  EXPECT_FALSE(w.pos_err_mean_deg || w.pos_err_min_deg || w.pos_err_max_deg || w.speed_err_rpm);
  ASSERT_FALSE(d.set_angle_deg(40));  // 36 deg at 30 deg/s: 1.2 s of slewing
  run_s(tw, 1.0);
  EXPECT_TRUE(d.telemetry().lock_lost) << "handed back before the angle reached 40 deg";
  run_s(tw, 0.4);
  EXPECT_FALSE(d.telemetry().lock_lost) << "not handed back at 40 deg";
  double worst = 0;
  for (int i = 0; i < 200; ++i) {
    run_s(tw, 0.01);
    const auto t = d.telemetry();
    EXPECT_FALSE(t.lock_lost) << "lost again at 40 deg";
    if (t.pos_err_deg) worst = std::max(worst, std::fabs(*t.pos_err_deg));
  }
  EXPECT_EQ(d.fault(), drivers::Fault::none);
  EXPECT_LT(worst, 10.0);
}

}  // namespace
}  // namespace synbench

namespace synbench {
namespace {

// The fresh EEMF-RLS the lock guard hands the rotor back to at 700 rpm starts its identification
// from P0 = 1e5 I. Its observer now runs on the constant Rs, L'd, Lq until the RLS has identified
// for `rls_warmup_s` and then glides to the estimates; on the first fits at once it lost the
// rotor again at two of these three noise seeds (fails with rls_warmup_s 0), braking the shaft
// to about 600 rpm before the guard caught it. With the default slow model and flux offsets
// (rls_model_filter_s, rls_flux_offset) it holds 76 deg here, even through a load step to
// 3.5 N m, so the lost point is made on the session-8 settings, which lose it.
TEST(ClosedLoopEstimators, AFreshEemfRlsHandedARunningRotorHoldsIt) {
  for (int seed : {1, 2, 3}) {
    emulator::TwinConfig cfg;
    cfg.sim.seed_int = seed;
    cfg.estimators.eemf.rls_model_filter_s = cfg.estimators.eemf.rls_estimate_filter_s;
    cfg.estimators.eemf.rls_flux_offset = false;
    emulator::Twin tw{cfg};
    auto& d = tw.synrm_drive();
    const std::string at = "seed " + std::to_string(seed);
    ASSERT_NO_FATAL_FAILURE(lose_the_rotor_at_76_deg(tw, drivers::Estimator::eemf_rls, 700, 1.5)) << at;
    ASSERT_FALSE(d.set_angle_deg(45));  // 31 deg at 30 deg/s, then the hand-back
    run_s(tw, 1.5);
    EXPECT_FALSE(d.telemetry().lock_lost) << at << ": not handed back, or lost again at once";
    double min_speed_rpm = 1e9;
    bool lost_again = false;
    for (int i = 0; i < 250 && !lost_again; ++i) {
      run_s(tw, 0.01);
      const auto t = d.telemetry();
      lost_again = t.lock_lost;
      EXPECT_FALSE(lost_again) << at << ": lost again at 45 deg after " << 1.5 + 0.01 * i << " s";
      min_speed_rpm = std::min(min_speed_rpm, t.speed_rpm);
    }
    EXPECT_EQ(d.fault(), drivers::Fault::none) << at;
    EXPECT_GT(min_speed_rpm, 640.0) << at;
  }
}

}  // namespace
}  // namespace synbench

namespace synbench {
namespace {

// EEMF-RLS's observer on the slow model with the RLS's flux offsets (the static q inductance and
// d flux the rotation terms and the magnitude need; docs/estimators.md) holds the 76 deg point
// the session-8 settings (0.2 s, incremental inductances only) lose; about 12 deg behind, as
// the sweeps show at the highest angles (docs/estimators.md).
TEST(ClosedLoopEstimators, EemfRlsOnItsSlowModelWithFluxOffsetsHolds76DegAt700Rpm) {
  for (bool slow_model : {false, true}) {
    emulator::TwinConfig cfg;
    if (!slow_model) {
      cfg.estimators.eemf.rls_model_filter_s = cfg.estimators.eemf.rls_estimate_filter_s;
      cfg.estimators.eemf.rls_flux_offset = false;
    }
    emulator::Twin tw{cfg};
    auto& d = tw.synrm_drive();
    ASSERT_FALSE(d.set_estimator(drivers::Estimator::eemf_rls));
    ASSERT_FALSE(d.set_angle_deg(45));
    ASSERT_FALSE(d.set_speed_rpm(700));
    ASSERT_FALSE(d.enable(true));
    ASSERT_FALSE(tw.load_drive().enable(true));
    run_s(tw, 1.5);
    for (int i = 1; i <= 8; ++i) {
      ASSERT_FALSE(tw.load_drive().set_torque_Nm(0.2 * i));
      run_s(tw, 0.1);
    }
    ASSERT_FALSE(d.set_angle_deg(76));
    run_s(tw, 3.0);
    d.begin_window(10000);
    run_s(tw, 1.0);
    const auto w = d.window_result();
    EXPECT_EQ(d.fault(), drivers::Fault::none);
    if (!slow_model) {
      EXPECT_GT(w.lock_lost_fraction, 0.5) << "the session-8 settings hold 76 deg: no comparison";
      continue;
    }
    EXPECT_EQ(w.lock_lost_fraction, 0.0);
    ASSERT_TRUE(w.pos_err_mean_deg && w.pos_err_min_deg && w.pos_err_max_deg);
    EXPECT_LT(std::fabs(*w.pos_err_mean_deg), 15.0);
    EXPECT_LT(*w.pos_err_max_deg - *w.pos_err_min_deg, 45.0);
    std::printf("eemf-rls 700 rpm 1.6 N m 76 deg: mean %+.2f [%+.1f, %+.1f] deg\n", *w.pos_err_mean_deg,
                *w.pos_err_min_deg, *w.pos_err_max_deg);
  }
}

}  // namespace
}  // namespace synbench
