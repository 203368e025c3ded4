// EKF-BASIC: Jacobians against finite differences, one step against a textbook dense EKF, and
// tracking of a synthetic rotor from the thesis initial state.
#include "emulator/firmware/estimators/ekf_basic.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include <Eigen/Dense>

#include "emulator/mcidc.hpp"
#include "emulator/noise.hpp"
#include "tests/emulator/estimators/ekf_test_util.hpp"

namespace synbench::emulator::firmware {
namespace {

using test::kOmega500;
using test::kPi;
using test::kTs;
using State = EkfBasic::State;
using Cov = EkfBasic::Cov;

State random_state(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  State x;
  x << 1.5 + 2.0 * u(rng), 4.0 + 6.0 * u(rng), -300.0 + 600.0 * u(rng), -kPi + 2.0 * kPi * u(rng);
  return x;
}

TEST(EkfBasic, ProcessJacobianMatchesFiniteDifferences) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    const State x = random_state(rng);
    const Cov analytic = EkfBasic::jacobian_f(kTs);
    const Cov numeric = test::numeric_jacobian<4, 4>(
        [](const State& s) { return EkfBasic::f(s, kTs); }, x);
    EXPECT_LT(test::max_relative_error(analytic, numeric), 1e-6) << "trial " << trial;
  }
}

TEST(EkfBasic, MeasurementJacobianMatchesFiniteDifferences) {
  std::mt19937_64 rng(12);
  double worst = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const State x = random_state(rng);
    for (int phase = 0; phase < 3; ++phase) {
      const EkfBasic::MeasRow analytic = EkfBasic::jacobian_h(x, phase);
      const EkfBasic::MeasRow numeric = test::numeric_jacobian<1, 4>(
          [phase](const State& s) { return Eigen::Matrix<double, 1, 1>(EkfBasic::h(s, phase)); },
          x);
      const double err = test::max_relative_error(analytic, numeric);
      worst = std::max(worst, err);
      EXPECT_LT(err, 1e-6) << "trial " << trial << " phase " << phase;
    }
  }
  RecordProperty("worst_relative_error", std::to_string(worst));
  std::printf("EKF-BASIC H: worst element relative error %.2e\n", worst);
}

TEST(EkfBasic, MeasurementModelIsThePhaseReluctance) {
  State x;
  x << 1.0 / 0.45, 1.0 / 0.12, 0.0, 0.7;
  for (int phase = 0; phase < 3; ++phase)
    EXPECT_NEAR(EkfBasic::h(x, phase), phase_reluctance(0.7, phase, 0.45, 0.12), 1e-12);
  // Phase a aligned with d sees R'd, with q sees R'q.
  x(EkfBasic::kTh) = 0.0;
  EXPECT_NEAR(EkfBasic::h(x, 0), 1.0 / 0.45, 1e-12);
  x(EkfBasic::kTh) = kPi / 2;
  EXPECT_NEAR(EkfBasic::h(x, 0), 1.0 / 0.12, 1e-12);
}

// One step of the filter equals the textbook EKF with dense matrices and a Joseph update.
TEST(EkfBasic, StepMatchesDenseReference) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const EkfBasicParams params;
  for (int trial = 0; trial < 10; ++trial) {
    State x = random_state(rng);
    x(EkfBasic::kTh) *= 0.9;  // keep the reference away from the +-pi wrap
    Cov a;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) a(i, j) = u(rng);
    const Cov p = a * a.transpose() + 0.1 * Cov::Identity();
    const int phase = trial % 3;
    EstimatorInput in;
    in.ts_s = kTs;
    in.mcidc_phase = phase;
    in.mcidc_reluctance_per_H = EkfBasic::h(x, phase) + 0.3 * u(rng);

    EkfBasic ekf(params);
    ekf.reset(x, p);
    ekf.update(in);

    Eigen::Vector4d qd(params.sigma_rel_per_H * params.sigma_rel_per_H,
                       params.sigma_rel_per_H * params.sigma_rel_per_H,
                       params.sigma_w_rad_s * params.sigma_w_rad_s, 0.0);
    const Cov f = EkfBasic::jacobian_f(kTs);
    const State xm = EkfBasic::f(x, kTs);
    const Cov pm = f * p * f.transpose() + Cov(qd.asDiagonal());
    const EkfBasic::MeasRow h = EkfBasic::jacobian_h(xm, phase);
    const double r = params.sigma_rph_per_H * params.sigma_rph_per_H;
    const double s = (h * pm * h.transpose())(0, 0) + r;
    const State k = pm * h.transpose() / s;
    const State xp = xm + k * (in.mcidc_reluctance_per_H - EkfBasic::h(xm, phase));
    const Cov ikh = Cov::Identity() - k * h;
    const Cov pp = ikh * pm * ikh.transpose() + k * r * k.transpose();

    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(ekf.state()(i), xp(i), 1e-10 * std::max(1.0, std::abs(xp(i))));
    EXPECT_NEAR(std::remainder(ekf.state()(EkfBasic::kTh) - xp(EkfBasic::kTh), 2 * kPi), 0.0,
                1e-10);
    EXPECT_LT((ekf.covariance() - pp).cwiseAbs().maxCoeff(), 1e-10 * pp.cwiseAbs().maxCoeff());
    EXPECT_EQ(ekf.covariance(), ekf.covariance().transpose());
  }
}

TEST(EkfBasic, PredictsOnlyWithoutSample) {
  EkfBasic ekf;
  State x;
  x << 2.2, 8.0, 100.0, 0.5;
  Cov p = Cov::Identity();
  ekf.reset(x, p);
  EstimatorInput in;
  in.ts_s = kTs;
  in.mcidc_reluctance_per_H = 1e6;  // must be ignored: no phase
  ekf.update(in);
  EXPECT_DOUBLE_EQ(ekf.state()(EkfBasic::kTh), 0.5 + kTs * 100.0);
  EXPECT_DOUBLE_EQ(ekf.state()(EkfBasic::kRd), 2.2);
  EXPECT_DOUBLE_EQ(ekf.covariance()(EkfBasic::kTh, EkfBasic::kTh), 1.0 + kTs * kTs);
  EXPECT_DOUBLE_EQ(ekf.covariance()(EkfBasic::kW, EkfBasic::kW), 1.0 + 0.096 * 0.096);
  in.mcidc_phase = 3;  // not a phase: ignored as well
  ekf.update(in);
  EXPECT_DOUBLE_EQ(ekf.state()(EkfBasic::kRq), 8.0);
}

TEST(EkfBasic, OutputsWrappedAngleAndInductances) {
  EkfBasic ekf;
  State x;
  x << 2.0, 5.0, 0.0, 3.0 * kPi / 2;  // 270 deg
  ekf.reset(x, Cov::Identity());
  const EstimatorOutput out = ekf.output();
  EXPECT_NEAR(out.theta_e_rad, -kPi / 2, 1e-12);
  ASSERT_TRUE(out.ld_H && out.lq_H);
  EXPECT_DOUBLE_EQ(*out.ld_H, 0.5);
  EXPECT_DOUBLE_EQ(*out.lq_H, 0.2);
  EXPECT_FALSE(out.rs_ohm);
  x(EkfBasic::kTh) = -kPi;
  ekf.reset(x, Cov::Identity());
  EXPECT_DOUBLE_EQ(ekf.output().theta_e_rad, kPi);  // (-pi, pi]
}

TEST(EkfBasic, DefaultsAreTheThesisSetup) {
  const EkfBasic ekf;
  EXPECT_EQ(ekf.state(), State(2.0, 2.0, 0.0, 0.0));
  EXPECT_EQ(ekf.covariance(), Cov(Eigen::Vector4d(0.01, 0.01, 100.0, 1.0).asDiagonal()));
}

// (R'd, R'q, th) and (R'q, R'd, th + pi/2) predict the same R'_phN. A filter started (or locked)
// with the axes swapped is mapped to Ld > Lq, and from then on it is exactly the swapped image of
// a filter that does not enforce the convention.
TEST(EkfBasic, SwappedAxesAreMappedToLdAboveLq) {
  constexpr double kLd = 0.45, kLq = 0.12;
  State swapped;
  swapped << 1.0 / kLq, 1.0 / kLd, 90.0, 0.2 + kPi / 2;
  Cov p = Cov(Eigen::Vector4d(1e-3, 2e-3, 10.0, 0.1).asDiagonal());
  p(EkfBasic::kRd, EkfBasic::kTh) = p(EkfBasic::kTh, EkfBasic::kRd) = 1e-3;
  EkfBasicParams free_params;
  free_params.enforce_ld_above_lq = false;
  EkfBasic free(free_params), canonical;
  free.reset(swapped, p);
  canonical.reset(swapped, p);
  Noise noise(5);
  for (int k = 1; k <= 300; ++k) {
    const double theta = 0.2 + 100.0 * k * kTs;
    EstimatorInput in;
    in.ts_s = kTs;
    in.mcidc_phase = k % 3;
    in.mcidc_reluctance_per_H = phase_reluctance(theta, k % 3, kLd, kLq) + 0.15 * noise.gauss();
    free.update(in);
    canonical.update(in);
  }
  const State& a = free.state();
  const State& b = canonical.state();
  EXPECT_LT(a(EkfBasic::kRq), a(EkfBasic::kRd));  // still swapped
  EXPECT_NEAR(b(EkfBasic::kRd), a(EkfBasic::kRq), 1e-9);
  EXPECT_NEAR(b(EkfBasic::kRq), a(EkfBasic::kRd), 1e-9);
  EXPECT_NEAR(b(EkfBasic::kW), a(EkfBasic::kW), 1e-9);
  EXPECT_NEAR(std::remainder(b(EkfBasic::kTh) - a(EkfBasic::kTh) - kPi / 2, 2 * kPi), 0.0, 1e-9);
  Cov ap = free.covariance();
  ap.row(0).swap(ap.row(1));
  ap.col(0).swap(ap.col(1));
  EXPECT_LT((canonical.covariance() - ap).cwiseAbs().maxCoeff(), 1e-12);
  const EstimatorOutput out = canonical.output();
  EXPECT_NEAR(*out.ld_H, kLd, 0.05 * kLd);
  EXPECT_NEAR(*out.lq_H, kLq, 0.05 * kLq);
  EXPECT_LT(std::abs(test::position_error_deg(out.theta_e_rad, 0.2 + 100.0 * 300 * kTs)), 5.0);
}

// Synthetic rotor at constant 500 rpm, true L'd = 0.45 H, L'q = 0.12 H, ASPWM phase cycling,
// MCIDC noise 0.15 1/H; the filter starts from the thesis x0 (standstill, 0.5 H both axes).
TEST(EkfBasic, TracksSyntheticRotor) {
  constexpr double kLd = 0.45, kLq = 0.12, kTheta0 = 1.0;
  EkfBasic ekf;
  Noise noise(20240501);
  const int steps = static_cast<int>(2.0 / kTs);
  const int tail = static_cast<int>(0.2 / kTs);
  double max_err = 0, sum_err = 0;
  for (int k = 1; k <= steps; ++k) {
    const double theta = kTheta0 + kOmega500 * k * kTs;
    EstimatorInput in;
    in.ts_s = kTs;
    in.mcidc_phase = k % 3;
    in.mcidc_reluctance_per_H = phase_reluctance(theta, k % 3, kLd, kLq) + 0.15 * noise.gauss();
    ekf.update(in);
    if (k > steps - tail) {
      const double e = test::position_error_deg(ekf.output().theta_e_rad, theta);
      max_err = std::max(max_err, std::abs(e));
      sum_err += e;
    }
  }
  const EstimatorOutput out = ekf.output();
  const double ld_err = *out.ld_H / kLd - 1.0, lq_err = *out.lq_H / kLq - 1.0;
  RecordProperty("max_position_error_deg", std::to_string(max_err));
  RecordProperty("mean_position_error_deg", std::to_string(sum_err / tail));
  RecordProperty("ld_error_pct", std::to_string(100 * ld_err));
  RecordProperty("lq_error_pct", std::to_string(100 * lq_err));
  std::printf("EKF-BASIC after 2 s: |pos err| max %.3f deg (mean %.3f) over last 0.2 s, "
              "Ld %+.2f %%, Lq %+.2f %%, w_e %.3f rad/s (true %.3f)\n",
              max_err, sum_err / tail, 100 * ld_err, 100 * lq_err, out.omega_e_rad_s, kOmega500);
  EXPECT_LT(max_err, 3.0);
  EXPECT_LT(std::abs(ld_err), 0.10);
  EXPECT_LT(std::abs(lq_err), 0.10);
  EXPECT_NEAR(out.omega_e_rad_s, kOmega500, 0.02 * kOmega500);
}

}  // namespace
}  // namespace synbench::emulator::firmware
