#include "emulator/firmware/estimators/ekf_basic.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "emulator/firmware/estimators/ekf_correct.hpp"
#include "emulator/mcidc.hpp"

namespace synbench::emulator::firmware {

namespace {

bool valid_phase(int phase) { return phase >= 0 && phase < 3; }

}  // namespace

EkfBasic::EkfBasic(const EkfBasicParams& params) : params_(params) {
  q_diag_ << params_.sigma_rel_per_H * params_.sigma_rel_per_H,
      params_.sigma_rel_per_H * params_.sigma_rel_per_H,
      params_.sigma_w_rad_s * params_.sigma_w_rad_s, params_.sigma_th_rad * params_.sigma_th_rad;
  r_ = params_.sigma_rph_per_H * params_.sigma_rph_per_H;
  reset();
}

EkfBasic::State EkfBasic::f(const State& x, double ts_s) {
  State y = x;
  y(kTh) += ts_s * x(kW);
  return y;
}

EkfBasic::Cov EkfBasic::jacobian_f(double ts_s) {
  Cov fm = Cov::Identity();
  fm(kTh, kW) = ts_s;
  return fm;
}

double EkfBasic::h(const State& x, int phase) {
  const double c = std::cos(x(kTh) + kPhaseOffsetRad[phase]);
  const double c2 = c * c;
  return x(kRd) * c2 + x(kRq) * (1.0 - c2);
}

EkfBasic::MeasRow EkfBasic::jacobian_h(const State& x, int phase) {
  const double phi = x(kTh) + kPhaseOffsetRad[phase];
  const double c = std::cos(phi), s = std::sin(phi);
  MeasRow hm;
  hm << c * c, s * s, 0.0, 2.0 * (x(kRq) - x(kRd)) * s * c;
  return hm;
}

void EkfBasic::update(const EstimatorInput& in) {
  const double ts = in.ts_s > 0 ? in.ts_s : params_.ts_s;

  // Predict. F = I + Ts e_th e_w^T, so F P F^T only touches row and column th.
  x_(kTh) += ts * x_(kW);
  p_.row(kTh) += ts * p_.row(kW);
  p_.col(kTh) += ts * p_.col(kW);
  p_.diagonal() += q_diag_;

  // Correct with the scalar MCIDC sample.
  if (in.mcidc_phase && valid_phase(*in.mcidc_phase)) {
    const int phase = *in.mcidc_phase;
    const double phi = x_(kTh) + kPhaseOffsetRad[phase];
    const double c = std::cos(phi), s = std::sin(phi);
    const double c2 = c * c, s2 = s * s;
    const double innovation =
        in.mcidc_reluctance_per_H - (x_(kRd) * c2 + x_(kRq) * s2);
    MeasRow hm;
    hm << c2, s2, 0.0, 2.0 * (x_(kRq) - x_(kRd)) * s * c;
    const State pht = p_ * hm.transpose();
    ekf_correct(x_, p_, pht, Eigen::Matrix<double, 1, 1>{hm.dot(pht) + r_},
                Eigen::Matrix<double, 1, 1>{innovation});
  }

  // (R'd, R'q, th) -> (R'q, R'd, th + pi/2) gives the same R'_phN for every phase.
  floor_and_order_reluctances(params_.min_reluctance_per_H, params_.enforce_ld_above_lq);
  x_(kTh) = wrap_pi(x_(kTh));
}

EstimatorOutput EkfBasic::output() const { return core_output(); }

}  // namespace synbench::emulator::firmware
