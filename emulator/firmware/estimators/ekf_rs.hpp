// EKF-RS position, speed, inductance and stator-resistance estimator (physics.md 8, thesis 5.64
// to 5.85).
//
// State x = [R'd, R'q, i_d, i_q, w_e, th_e, Rs], input u_alpha,beta (turned into u_dq by Park
// with the estimated angle, so the process Jacobian has d/d th_e terms). Process (Euler):
//   i_d += Ts R'd (u_d - Rs i_d + w_e Psi_q),  i_q += Ts R'q (u_q - Rs i_q - w_e Psi_d),
//   th_e += Ts w_e, the rest constant.
// The flux in the rotational (back-EMF) terms is, as in the thesis, Psi = i / R' (linear machine)
// unless the drive's flux maps are given: then Psi_d(i_d), Psi_q(i_q) from the maps (apparent
// inductances), while the reluctances R' = 1/L' (incremental, what the MCIDC measures) stay on
// di/dt. On a saturated machine the linear model's back-EMF is wrong by w (Psi - L' i), volts
// that Rs absorbs (up to 320 % at 3.5 N m); with the maps Rs is the only unknown left in the
// voltage balance (docs/estimators.md).
// Measurements y = [R'_phN, i_alpha, i_beta] with the MCIDC sample, [i_alpha, i_beta] without.
// Rs gets process noise only while |w_e| is above a speed threshold (thesis Fig. 5.21). The model
// is invariant under (th_e + pi, -i_d, -i_q), so the filter may lock at th_e + pi (valid for a
// SynRM). It is also exactly invariant under (R'd <-> R'q, i_d -> i_q, i_q -> -i_d,
// th_e + pi/2): from the symmetric thesis x0 the filter can lock with the axes swapped. With
// enforce_ld_above_lq (default) the filter keeps to the convention Ld > Lq (physics.md 0) by
// applying that symmetry to the state and covariance whenever R'd > R'q; for the linear model
// this is an exact change of coordinates, not a correction (with the flux maps, a re-labelling
// onto the axes the maps assume).
#pragma once

#include <array>
#include <numbers>
#include <optional>

#include <Eigen/Core>

#include "emulator/firmware/estimators/ekf_core.hpp"
#include "emulator/firmware/estimators/estimator.hpp"
#include "emulator/flux_map.hpp"
#include "emulator/twin_config.hpp"

namespace synbench::emulator::firmware {

// Thesis defaults (Table 5.2, eq. 5.85). Standard deviations; variances are per PWM step.
struct EkfRsParams {
  double ts_s = 1e-4;               // step used when EstimatorInput::ts_s is not positive
  double sigma_rph_per_H = 0.15;    // MCIDC measurement noise
  double sigma_i_A = 0.0158;        // phase-current noise (R and Q use (2/3) sigma_i^2)
  double sigma_rel_per_H = 5e-4;    // process noise of R'd and R'q
  double sigma_w_rad_s = 0.096;     // process noise of w_e: Ts T_nom / J_tot
  double sigma_th_rad = 0.0;        // process noise of th_e
  double sigma_rs_ohm = 5e-3;       // process noise of Rs above the speed threshold
  // [assumed] |w_e| below which Rs is frozen (sigma_Rs = 0): 100 rpm with 2 pole pairs.
  double rs_speed_threshold_rad_s = 2.0 * std::numbers::pi * 100.0 / 60.0 * 2.0;
  double min_reluctance_per_H = 0.05;  // floor on R'd, R'q (keeps L = 1/R' finite)
  double min_rs_ohm = 0.0;             // floor on Rs
  bool enforce_ld_above_lq = true;     // keep the d axis on the larger inductance
  // The drive's flux maps for the back-EMF terms; both unset = the thesis' linear model.
  std::optional<FluxAxisParams> flux_d, flux_q;
  std::array<double, 7> x0{2.0, 2.0, 0.0, 0.0, 0.0, 0.0, 5.0};
  std::array<double, 7> p0_diag{0.01, 0.01, 1.0, 1.0, 100.0, 1.0, 0.01};
};

namespace ekf_rs {
enum Index : int { kRd = 0, kRq = 1, kId = 2, kIq = 3, kW = 4, kTh = 5, kRs = 6 };
}

class EkfRs final : public Estimator, public EkfCore<7, ekf_rs::kRd, ekf_rs::kRq, ekf_rs::kW, ekf_rs::kTh> {
 public:
  using Index = ekf_rs::Index;
  using enum ekf_rs::Index;
  using Meas3 = Eigen::Vector3d;                    // [R'_phN, i_alpha, i_beta]
  using Jac3 = Eigen::Matrix<double, 3, kN>;
  using Meas2 = Eigen::Vector2d;                    // [i_alpha, i_beta]
  using Jac2 = Eigen::Matrix<double, 2, kN>;

  explicit EkfRs(const EkfRsParams& params = {});

  // One PWM period: predict over in.ts_s (params.ts_s if not positive) with the voltage
  // in.ualpha/ubeta applied during it, then correct with i_alpha,beta and, if in.mcidc_phase is
  // set (0, 1, 2 = a, b, c), the MCIDC sample.
  void update(const EstimatorInput& in) override;
  // Angle wrapped to (-pi, pi]; Ld = 1/R'd, Lq = 1/R'q, Rs.
  EstimatorOutput output() const override;

  // Back to x0/P0 from the params (EkfCore::reset(x, p): to a given state and covariance).
  void reset() { reset_diagonal(params_.x0, params_.p0_diag); }
  using EkfCore::reset;
  const EkfRsParams& params() const { return params_; }

  // Flux of the back-EMF terms: the maps, or null for Psi = i / R'.
  struct FluxMaps {
    FluxAxis d, q;
  };

  // The model, public so tests can check the Jacobians against finite differences.
  // u_alpha, u_beta are stationary-frame voltages; Park uses x's th_e.
  static State f(const State& x, double ualpha_V, double ubeta_V, double ts_s,
                 const FluxMaps* maps = nullptr);
  static Cov jacobian_f(const State& x, double ualpha_V, double ubeta_V, double ts_s,
                        const FluxMaps* maps = nullptr);
  const FluxMaps* flux_maps() const { return maps_ ? &*maps_ : nullptr; }
  static Meas3 h(const State& x, int phase);
  static Jac3 jacobian_h(const State& x, int phase);
  static Meas2 h_currents(const State& x);
  static Jac2 jacobian_h_currents(const State& x);

 private:
  template <int M>
  void correct(const Eigen::Matrix<double, M, 1>& innovation,
               const Eigen::Matrix<double, M, kN>& hm,
               const Eigen::Matrix<double, M, 1>& r_diag,
               const std::array<std::array<int, 3>, M>& nonzero);

  EkfRsParams params_;
  std::optional<FluxMaps> maps_;
  State q_diag_;       // with sigma_Rs
  double r_rph_, r_i_;
};

}  // namespace synbench::emulator::firmware
