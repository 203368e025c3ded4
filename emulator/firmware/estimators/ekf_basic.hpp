// EKF-BASIC position, speed and inductance estimator (physics.md 8, thesis 5.46 to 5.63).
//
// State x = [R'd, R'q, w_e, th_e] (R' = 1/L' in 1/H), no input. Process: reluctances and speed
// constant, th_e += Ts w_e (F = I with F[th][w] = Ts). Measurement: the one MCIDC sample of the
// period, h = R'd cos^2(th_e + th_phN) + R'q sin^2(th_e + th_phN); without a sample the filter
// only predicts. The reluctance depends on 2 th_e, so the filter may lock at th_e or th_e + pi;
// both are valid for a SynRM (the analysis wraps the position error to (-90, 90] deg).
// The model is also exactly symmetric under (R'd <-> R'q, th_e + pi/2): from the symmetric thesis
// x0 the filter can lock with the axes swapped. With enforce_ld_above_lq (default) the filter
// keeps to the convention Ld > Lq (physics.md 0) by applying that symmetry to the state and
// covariance whenever R'd > R'q; this is an exact change of coordinates, not a correction.
#pragma once

#include <array>

#include <Eigen/Core>

#include "emulator/firmware/estimators/ekf_core.hpp"
#include "emulator/firmware/estimators/estimator.hpp"

namespace synbench::emulator::firmware {

// Thesis defaults (Table 5.1). Variances are per PWM step.
struct EkfBasicParams {
  double ts_s = 1e-4;               // step used when EstimatorInput::ts_s is not positive
  double sigma_rph_per_H = 0.15;    // MCIDC measurement noise
  double sigma_rel_per_H = 5e-4;    // process noise of R'd and R'q
  double sigma_w_rad_s = 0.096;     // process noise of w_e: Ts T_nom / J_tot
  double sigma_th_rad = 0.0;        // process noise of th_e
  double min_reluctance_per_H = 0.05;  // floor on R'd, R'q (keeps L = 1/R' finite)
  bool enforce_ld_above_lq = true;     // keep the d axis on the larger inductance
  std::array<double, 4> x0{2.0, 2.0, 0.0, 0.0};
  std::array<double, 4> p0_diag{0.01, 0.01, 100.0, 1.0};
};

namespace ekf_basic {
enum Index : int { kRd = 0, kRq = 1, kW = 2, kTh = 3 };
}

class EkfBasic final : public Estimator, public EkfCore<4, ekf_basic::kRd, ekf_basic::kRq, ekf_basic::kW, ekf_basic::kTh> {
 public:
  using Index = ekf_basic::Index;
  using enum ekf_basic::Index;
  using MeasRow = Eigen::Matrix<double, 1, kN>;

  explicit EkfBasic(const EkfBasicParams& params = {});

  // One PWM period: predict over in.ts_s (params.ts_s if not positive), then correct with the
  // MCIDC sample if in.mcidc_phase is set (phase 0, 1, 2 = a, b, c; others are ignored).
  void update(const EstimatorInput& in) override;
  // Angle wrapped to (-pi, pi]; Ld = 1/R'd, Lq = 1/R'q; no Rs.
  EstimatorOutput output() const override;

  // Back to x0/P0 from the params (EkfCore::reset(x, p): to a given state and covariance).
  void reset() { reset_diagonal(params_.x0, params_.p0_diag); }
  using EkfCore::reset;
  const EkfBasicParams& params() const { return params_; }

  // The model, public so tests can check the Jacobians against finite differences.
  static State f(const State& x, double ts_s);
  static Cov jacobian_f(double ts_s);
  // Normalized reluctance of phase `phase` (0 a, 1 b, 2 c; emulator/mcidc.hpp offsets).
  static double h(const State& x, int phase);
  static MeasRow jacobian_h(const State& x, int phase);

 private:
  EkfBasicParams params_;
  State q_diag_;
  double r_;
};

}  // namespace synbench::emulator::firmware
