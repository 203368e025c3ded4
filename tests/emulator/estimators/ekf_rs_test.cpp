// EKF-RS: Jacobians against finite differences, one step against a textbook dense EKF, the Rs
// noise speed threshold, and convergence on a synthetic current-controlled SynRM.
#include "emulator/firmware/estimators/ekf_rs.hpp"

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
using State = EkfRs::State;
using Cov = EkfRs::Cov;
using E = EkfRs;

State random_state(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  State x;
  x << 1.5 + 2.0 * u(rng), 4.0 + 6.0 * u(rng), -3.0 + 6.0 * u(rng), -3.0 + 6.0 * u(rng),
      -300.0 + 600.0 * u(rng), -kPi + 2.0 * kPi * u(rng), 5.0 + 10.0 * u(rng);
  return x;
}

TEST(EkfRs, ProcessJacobianMatchesFiniteDifferences) {
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> uv(-300.0, 300.0);
  double worst = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const State x = random_state(rng);
    const double ua = uv(rng), ub = uv(rng);
    const Cov analytic = E::jacobian_f(x, ua, ub, kTs);
    const Cov numeric = test::numeric_jacobian<7, 7>(
        [ua, ub](const State& s) { return E::f(s, ua, ub, kTs); }, x);
    const double err = test::max_relative_error(analytic, numeric);
    worst = std::max(worst, err);
    EXPECT_LT(err, 1e-6) << "trial " << trial;
  }
  RecordProperty("worst_relative_error", std::to_string(worst));
  std::printf("EKF-RS F: worst element relative error %.2e\n", worst);
}

// The same with the drive's flux maps in the back-EMF terms (the twin's configuration): the
// rotational terms then take Psi(i) and L'(i) from the maps instead of i / R'.
TEST(EkfRs, ProcessJacobianWithFluxMapsMatchesFiniteDifferences) {
  const TwinConfig cfg;
  const EkfRs::FluxMaps maps{FluxAxis(cfg.synrm.flux_d), FluxAxis(cfg.synrm.flux_q)};
  std::mt19937_64 rng(22);
  std::uniform_real_distribution<double> uv(-300.0, 300.0);
  double worst = 0;
  for (int trial = 0; trial < 50; ++trial) {
    State x = random_state(rng);
    // L' of the maps jumps at the branch switch: a central difference across it means nothing.
    auto near_kink = [](double i, const FluxAxis& a) {
      return std::abs(std::abs(i) - a.switch_current_A()) < 1e-3;
    };
    while (near_kink(x(E::kId), maps.d) || near_kink(x(E::kIq), maps.q)) x = random_state(rng);
    const double ua = uv(rng), ub = uv(rng);
    const Cov analytic = E::jacobian_f(x, ua, ub, kTs, &maps);
    const Cov numeric = test::numeric_jacobian<7, 7>(
        [&](const State& s) { return E::f(s, ua, ub, kTs, &maps); }, x);
    const double err = test::max_relative_error(analytic, numeric);
    worst = std::max(worst, err);
    EXPECT_LT(err, 1e-6) << "trial " << trial << " x " << x.transpose();
  }
  // The maps do change the model: saturated Psi_q(1.5 A) is not 1.5 A / R'q.
  State x;
  x << 2.0, 8.0, 0.5, 1.5, 200.0, 0.0, 9.68;
  EXPECT_GT((E::f(x, 0, 0, kTs, &maps) - E::f(x, 0, 0, kTs)).cwiseAbs().maxCoeff(), 1e-3);
  std::printf("EKF-RS F with flux maps: worst element relative error %.2e\n", worst);
}

// The Park transform of the input is inside f, so d i_d/d th_e = Ts R'd u_q and
// d i_q/d th_e = -Ts R'q u_d (physics.md 8).
TEST(EkfRs, ProcessJacobianHasParkAngleTerms) {
  State x;
  x << 2.0, 8.0, 0.5, 1.0, 100.0, 0.4, 9.68;
  const double ua = 120.0, ub = -40.0;
  const double ud = std::cos(0.4) * ua + std::sin(0.4) * ub;
  const double uq = -std::sin(0.4) * ua + std::cos(0.4) * ub;
  const Cov f = E::jacobian_f(x, ua, ub, kTs);
  EXPECT_NEAR(f(E::kId, E::kTh), kTs * 2.0 * uq, 1e-15);
  EXPECT_NEAR(f(E::kIq, E::kTh), -kTs * 8.0 * ud, 1e-15);
  EXPECT_EQ(f(E::kTh, E::kW), kTs);
}

TEST(EkfRs, MeasurementJacobiansMatchFiniteDifferences) {
  std::mt19937_64 rng(22);
  double worst = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const State x = random_state(rng);
    for (int phase = 0; phase < 3; ++phase) {
      const E::Jac3 analytic = E::jacobian_h(x, phase);
      const E::Jac3 numeric = test::numeric_jacobian<3, 7>(
          [phase](const State& s) { return E::h(s, phase); }, x);
      const double err = test::max_relative_error(analytic, numeric);
      worst = std::max(worst, err);
      EXPECT_LT(err, 1e-6) << "trial " << trial << " phase " << phase;
    }
    const E::Jac2 analytic2 = E::jacobian_h_currents(x);
    const E::Jac2 numeric2 =
        test::numeric_jacobian<2, 7>([](const State& s) { return E::h_currents(s); }, x);
    const double err2 = test::max_relative_error(analytic2, numeric2);
    worst = std::max(worst, err2);
    EXPECT_LT(err2, 1e-6) << "trial " << trial << " currents only";
  }
  RecordProperty("worst_relative_error", std::to_string(worst));
  std::printf("EKF-RS H: worst element relative error %.2e\n", worst);
}

TEST(EkfRs, MeasurementModel) {
  State x;
  x << 1.0 / 0.45, 1.0 / 0.12, 0.75, 1.3, 0.0, 0.9, 9.68;
  for (int phase = 0; phase < 3; ++phase) {
    const E::Meas3 y = E::h(x, phase);
    EXPECT_NEAR(y(0), phase_reluctance(0.9, phase, 0.45, 0.12), 1e-12);
    EXPECT_NEAR(y(1), std::cos(0.9) * 0.75 - std::sin(0.9) * 1.3, 1e-12);
    EXPECT_NEAR(y(2), std::sin(0.9) * 0.75 + std::cos(0.9) * 1.3, 1e-12);
    EXPECT_EQ(y.tail<2>(), E::h_currents(x));
  }
}

// Textbook EKF with dense matrices and a Joseph update, for one step.
struct Reference {
  State x;
  Cov p;
};

Reference reference_step(const EkfRsParams& prm, const State& x, const Cov& p,
                         const EstimatorInput& in) {
  const double vi = (2.0 / 3.0) * prm.sigma_i_A * prm.sigma_i_A;
  const double vr = prm.sigma_rel_per_H * prm.sigma_rel_per_H;
  const bool rs_free = std::abs(x(E::kW)) >= prm.rs_speed_threshold_rad_s;
  State qd;
  qd << vr, vr, vi, vi, prm.sigma_w_rad_s * prm.sigma_w_rad_s, 0.0,
      rs_free ? prm.sigma_rs_ohm * prm.sigma_rs_ohm : 0.0;
  const Cov f = E::jacobian_f(x, in.ualpha_V, in.ubeta_V, in.ts_s);
  const State xm = E::f(x, in.ualpha_V, in.ubeta_V, in.ts_s);
  const Cov pm = f * p * f.transpose() + Cov(qd.asDiagonal());
  Eigen::MatrixXd h, r;
  Eigen::VectorXd innov;
  if (in.mcidc_phase) {
    h = E::jacobian_h(xm, *in.mcidc_phase);
    r = Eigen::Vector3d(prm.sigma_rph_per_H * prm.sigma_rph_per_H, vi, vi).asDiagonal();
    innov = Eigen::Vector3d(in.mcidc_reluctance_per_H, in.ialpha_A, in.ibeta_A) -
            E::h(xm, *in.mcidc_phase);
  } else {
    h = E::jacobian_h_currents(xm);
    r = Eigen::Vector2d(vi, vi).asDiagonal();
    innov = Eigen::Vector2d(in.ialpha_A, in.ibeta_A) - E::h_currents(xm);
  }
  const Eigen::MatrixXd k = pm * h.transpose() * (h * pm * h.transpose() + r).inverse();
  const Cov ikh = Cov::Identity() - k * h;
  return {xm + k * innov, ikh * pm * ikh.transpose() + k * r * k.transpose()};
}

void expect_step_matches_reference(bool with_mcidc, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const EkfRsParams params;
  for (int trial = 0; trial < 10; ++trial) {
    State x = random_state(rng);
    x(E::kTh) *= 0.9;  // keep the reference away from the +-pi wrap
    Cov a;
    for (int i = 0; i < 7; ++i)
      for (int j = 0; j < 7; ++j) a(i, j) = u(rng);
    const Cov p = 0.1 * a * a.transpose() + 0.01 * Cov::Identity();
    EstimatorInput in;
    in.ts_s = kTs;
    in.ualpha_V = 200.0 * u(rng);
    in.ubeta_V = 200.0 * u(rng);
    const E::Meas2 i = E::h_currents(E::f(x, in.ualpha_V, in.ubeta_V, kTs));
    in.ialpha_A = i(0) + 0.05 * u(rng);
    in.ibeta_A = i(1) + 0.05 * u(rng);
    if (with_mcidc) {
      in.mcidc_phase = trial % 3;
      in.mcidc_reluctance_per_H = E::h(x, trial % 3)(0) + 0.3 * u(rng);
    }
    EkfRs ekf(params);
    ekf.reset(x, p);
    ekf.update(in);
    const Reference ref = reference_step(params, x, p, in);
    for (int n = 0; n < 7; ++n) {
      if (n == E::kTh) continue;
      EXPECT_NEAR(ekf.state()(n), ref.x(n), 1e-9 * std::max(1.0, std::abs(ref.x(n))))
          << "trial " << trial << " state " << n;
    }
    EXPECT_NEAR(std::remainder(ekf.state()(E::kTh) - ref.x(E::kTh), 2 * kPi), 0.0, 1e-9);
    EXPECT_LT((ekf.covariance() - ref.p).cwiseAbs().maxCoeff(),
              1e-9 * ref.p.cwiseAbs().maxCoeff())
        << "trial " << trial;
    EXPECT_EQ(ekf.covariance(), ekf.covariance().transpose());
  }
}

TEST(EkfRs, StepWithMcidcMatchesDenseReference) { expect_step_matches_reference(true, 23); }
TEST(EkfRs, StepWithoutMcidcMatchesDenseReference) { expect_step_matches_reference(false, 24); }

// With i_d = i_q = 0 and Rs uncorrelated, Rs is decoupled from the rest: its variance grows by
// exactly sigma_Rs^2 above the speed threshold and not at all below it.
TEST(EkfRs, RsProcessNoiseOnlyAboveSpeedThreshold) {
  EkfRsParams params;
  params.rs_speed_threshold_rad_s = 50.0;
  for (const double w : {0.0, 49.0, -49.0, 51.0, -51.0, 300.0}) {
    EkfRs ekf(params);
    State x;
    x << 2.0, 5.0, 0.0, 0.0, w, 0.3, 9.0;
    ekf.reset(x, 0.02 * Cov::Identity());
    EstimatorInput in;
    in.ts_s = kTs;
    ekf.update(in);
    const double expected = 0.02 + (std::abs(w) >= 50.0 ? 5e-3 * 5e-3 : 0.0);
    EXPECT_NEAR(ekf.covariance()(E::kRs, E::kRs), expected, 1e-15) << "w_e " << w;
    EXPECT_EQ(ekf.state()(E::kRs), 9.0);
  }
}

// (R'd, R'q, i_d, i_q, th) and (R'q, R'd, i_q, -i_d, th + pi/2) have the same f and h. A filter
// started (or locked) with the axes swapped is mapped to Ld > Lq, and from then on it is exactly
// the image of a filter that does not enforce the convention.
TEST(EkfRs, SwappedAxesAreMappedToLdAboveLq) {
  State truth;
  truth << 1.0 / 0.45, 1.0 / 0.12, 0.75, 1.3, 100.0, 0.4, 9.68;
  State swapped = truth;
  swapped(E::kRd) = truth(E::kRq);
  swapped(E::kRq) = truth(E::kRd);
  swapped(E::kId) = truth(E::kIq);
  swapped(E::kIq) = -truth(E::kId);
  swapped(E::kTh) = truth(E::kTh) + kPi / 2;
  swapped(E::kRs) = 8.0;
  std::mt19937_64 rng(25);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Cov a;
  for (int i = 0; i < 7; ++i)
    for (int j = 0; j < 7; ++j) a(i, j) = u(rng);
  const Cov p = 0.01 * a * a.transpose() + 0.001 * Cov::Identity();
  EkfRsParams free_params;
  free_params.enforce_ld_above_lq = false;
  EkfRs free(free_params), canonical;
  free.reset(swapped, p);
  canonical.reset(swapped, p);
  for (int k = 1; k <= 300; ++k) {
    EstimatorInput in;
    in.ts_s = kTs;
    in.ualpha_V = 100.0 * u(rng);
    in.ubeta_V = 100.0 * u(rng);
    truth = E::f(truth, in.ualpha_V, in.ubeta_V, kTs);
    const E::Meas3 y = E::h(truth, k % 3);
    in.ialpha_A = y(1) + 0.01 * u(rng);
    in.ibeta_A = y(2) + 0.01 * u(rng);
    if (k % 5 != 0) {  // some periods without an MCIDC sample
      in.mcidc_phase = k % 3;
      in.mcidc_reluctance_per_H = y(0) + 0.1 * u(rng);
    }
    free.update(in);
    canonical.update(in);
  }
  const State& fa = free.state();
  const State& cb = canonical.state();
  EXPECT_LT(fa(E::kRq), fa(E::kRd));  // still swapped
  EXPECT_NEAR(cb(E::kRd), fa(E::kRq), 1e-8);
  EXPECT_NEAR(cb(E::kRq), fa(E::kRd), 1e-8);
  EXPECT_NEAR(cb(E::kId), fa(E::kIq), 1e-8);
  EXPECT_NEAR(cb(E::kIq), -fa(E::kId), 1e-8);
  EXPECT_NEAR(cb(E::kW), fa(E::kW), 1e-8);
  EXPECT_NEAR(cb(E::kRs), fa(E::kRs), 1e-8);
  EXPECT_NEAR(std::remainder(cb(E::kTh) - fa(E::kTh) - kPi / 2, 2 * kPi), 0.0, 1e-9);
  Cov jac = Cov::Zero();  // the signed permutation from `free` to `canonical`
  jac(E::kRd, E::kRq) = jac(E::kRq, E::kRd) = 1.0;
  jac(E::kId, E::kIq) = 1.0;
  jac(E::kIq, E::kId) = -1.0;
  jac(E::kW, E::kW) = jac(E::kTh, E::kTh) = jac(E::kRs, E::kRs) = 1.0;
  const Cov mapped = jac * free.covariance() * jac.transpose();
  EXPECT_LT((canonical.covariance() - mapped).cwiseAbs().maxCoeff(), 1e-10);
  const EstimatorOutput out = canonical.output();
  EXPECT_GT(*out.ld_H, *out.lq_H);
  EXPECT_LT(std::abs(test::position_error_deg(out.theta_e_rad, truth(E::kTh))), 2.0);
}

TEST(EkfRs, DefaultsAreTheThesisSetup) {
  const EkfRs ekf;
  State x0;
  x0 << 2.0, 2.0, 0.0, 0.0, 0.0, 0.0, 5.0;
  State p0;
  p0 << 0.01, 0.01, 1.0, 1.0, 100.0, 1.0, 0.01;
  EXPECT_EQ(ekf.state(), x0);
  EXPECT_EQ(ekf.covariance(), Cov(p0.asDiagonal()));
  const EstimatorOutput out = ekf.output();
  ASSERT_TRUE(out.ld_H && out.lq_H && out.rs_ohm);
  EXPECT_DOUBLE_EQ(*out.ld_H, 0.5);
  EXPECT_DOUBLE_EQ(*out.rs_ohm, 5.0);
}

// Linear SynRM in the rotor frame (Ld, Lq, Rs constant) at a constant 500 rpm, current vector
// 1.5 A at 60 deg held by a PI current controller on the TRUE angle. The EKF sees the applied
// u_alpha,beta, the phase currents with 15.8 mA noise per phase and one noisy R'_ph per period
// (ASPWM cycling), and starts from the thesis x0 (standstill, 0.5 H, Rs = 5 ohm).
struct SynrmRun {
  double max_pos_err_deg = 0, mean_pos_err_deg = 0;
  double rs_err = 0, ld_err = 0, lq_err = 0, w_err = 0;
};

SynrmRun run_synthetic_synrm(double seconds, std::uint64_t seed) {
  constexpr double kLd = 0.45, kLq = 0.12, kRs = 9.68;
  constexpr double kSigmaI = 0.0158, kSigmaRph = 0.15;
  constexpr double kIm = 1.5, kAngle = 60.0 * kPi / 180.0;
  constexpr double w = kOmega500;
  constexpr int kSub = 10;  // plant RK4 substeps per PWM period
  const double id_ref = kIm * std::cos(kAngle), iq_ref = kIm * std::sin(kAngle);
  const double bw = 2.0 * kPi * 40.0;  // current-loop bandwidth, pole-zero cancellation
  const double kp_d = bw * kLd, kp_q = bw * kLq, ki = bw * kRs;

  EkfRs ekf;
  Noise noise(seed);
  double theta = 0.8, id = 0.0, iq = 0.0;  // plant
  double int_d = 0.0, int_q = 0.0;         // PI integrators
  double ua_applied = 0.0, ub_applied = 0.0;
  const int steps = static_cast<int>(seconds / kTs);
  const int tail = static_cast<int>(0.5 / kTs);
  SynrmRun run;
  double sum_err = 0, sum_rs = 0, sum_ld = 0, sum_lq = 0, sum_w = 0;

  for (int k = 1; k <= steps; ++k) {
    // Plant over the period that just ended, with the voltage held in the stationary frame.
    const double dt = kTs / kSub;
    auto deriv = [&](double th, double d, double q, double& dd, double& dq) {
      const double ud = std::cos(th) * ua_applied + std::sin(th) * ub_applied;
      const double uq = -std::sin(th) * ua_applied + std::cos(th) * ub_applied;
      dd = (ud - kRs * d + w * kLq * q) / kLd;
      dq = (uq - kRs * q - w * kLd * d) / kLq;
    };
    for (int sub = 0; sub < kSub; ++sub) {
      double d1, q1, d2, q2, d3, q3, d4, q4;
      deriv(theta, id, iq, d1, q1);
      deriv(theta + 0.5 * dt * w, id + 0.5 * dt * d1, iq + 0.5 * dt * q1, d2, q2);
      deriv(theta + 0.5 * dt * w, id + 0.5 * dt * d2, iq + 0.5 * dt * q2, d3, q3);
      deriv(theta + dt * w, id + dt * d3, iq + dt * q3, d4, q4);
      id += dt / 6.0 * (d1 + 2 * d2 + 2 * d3 + d4);
      iq += dt / 6.0 * (q1 + 2 * q2 + 2 * q3 + q4);
      theta += dt * w;
    }

    // Sensors: three noisy phase currents (amplitude-invariant Clarke), one MCIDC sample.
    const double c = std::cos(theta), s = std::sin(theta);
    const double ial = c * id - s * iq, ibe = s * id + c * iq;
    const double ia = ial + kSigmaI * noise.gauss();
    const double ib = -0.5 * ial + std::sqrt(3.0) / 2 * ibe + kSigmaI * noise.gauss();
    const double ic = -0.5 * ial - std::sqrt(3.0) / 2 * ibe + kSigmaI * noise.gauss();
    const double ial_m = (2.0 / 3.0) * (ia - 0.5 * ib - 0.5 * ic);
    const double ibe_m = (ib - ic) / std::sqrt(3.0);

    EstimatorInput in;
    in.ts_s = kTs;
    in.ialpha_A = ial_m;
    in.ibeta_A = ibe_m;
    in.ualpha_V = ua_applied;
    in.ubeta_V = ub_applied;
    in.mcidc_phase = k % 3;
    in.mcidc_reluctance_per_H =
        phase_reluctance(theta, k % 3, kLd, kLq) + kSigmaRph * noise.gauss();
    ekf.update(in);

    // PI current control on the true angle, with decoupling feedforward.
    const double id_m = c * ial_m + s * ibe_m, iq_m = -s * ial_m + c * ibe_m;
    const double ed = id_ref - id_m, eq = iq_ref - iq_m;
    int_d += ki * ed * kTs;
    int_q += ki * eq * kTs;
    const double ud = kp_d * ed + int_d - w * kLq * iq_ref;
    const double uq = kp_q * eq + int_q + w * kLd * id_ref;
    const double th_mid = theta + 0.5 * w * kTs;  // voltage acts over the coming period
    ua_applied = std::cos(th_mid) * ud - std::sin(th_mid) * uq;
    ub_applied = std::sin(th_mid) * ud + std::cos(th_mid) * uq;

    if (k > steps - tail) {
      const EstimatorOutput out = ekf.output();
      const double e = test::position_error_deg(out.theta_e_rad, theta);
      run.max_pos_err_deg = std::max(run.max_pos_err_deg, std::abs(e));
      sum_err += e;
      sum_rs += *out.rs_ohm / kRs - 1.0;
      sum_ld += *out.ld_H / kLd - 1.0;
      sum_lq += *out.lq_H / kLq - 1.0;
      sum_w += out.omega_e_rad_s / w - 1.0;
    }
  }
  run.mean_pos_err_deg = sum_err / tail;
  run.rs_err = sum_rs / tail;
  run.ld_err = sum_ld / tail;
  run.lq_err = sum_lq / tail;
  run.w_err = sum_w / tail;
  return run;
}

TEST(EkfRs, ConvergesOnSyntheticSynrm) {
  const SynrmRun run = run_synthetic_synrm(4.0, 777);
  RecordProperty("max_position_error_deg", std::to_string(run.max_pos_err_deg));
  RecordProperty("rs_error_pct", std::to_string(100 * run.rs_err));
  RecordProperty("ld_error_pct", std::to_string(100 * run.ld_err));
  RecordProperty("lq_error_pct", std::to_string(100 * run.lq_err));
  std::printf("EKF-RS after 4 s (means over the last 0.5 s): |pos err| max %.3f deg (mean %.3f), "
              "Rs %+.2f %%, Ld %+.2f %%, Lq %+.2f %%, w_e %+.3f %%\n",
              run.max_pos_err_deg, run.mean_pos_err_deg, 100 * run.rs_err, 100 * run.ld_err,
              100 * run.lq_err, 100 * run.w_err);
  EXPECT_LT(run.max_pos_err_deg, 5.0);
  EXPECT_LT(std::abs(run.rs_err), 0.20);
  EXPECT_LT(std::abs(run.ld_err), 0.30);
  EXPECT_LT(std::abs(run.lq_err), 0.30);
  EXPECT_LT(std::abs(run.w_err), 0.02);
}

}  // namespace
}  // namespace synbench::emulator::firmware
