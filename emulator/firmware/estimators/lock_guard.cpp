// The drive's lock guard around a sensorless estimator.
#include "emulator/firmware/estimators/lock_guard.hpp"

#include <cmath>

namespace synbench::emulator::firmware {
namespace {

// Within the guard angle this long before the angle guard arms [assumed].
constexpr double kArm_s = 0.05;
// Not yet armed, off the encoder's speed by more than the guard speed this long: the estimator
// never found the rotor [assumed].
constexpr double kUnfound_s = 0.2;

}  // namespace

LockGuard::LockGuard(Factory make, double guard_rad, double guard_speed_rad_s, double guard_s,
                     double guard_current_A, double ts_s)
    : make_(std::move(make)), inner_(make_()), guard_rad_(guard_rad),
      guard_speed_rad_s_(guard_speed_rad_s), guard_current_A_(guard_current_A),
      guard_steps_(std::max(1L, std::lround(guard_s / ts_s))),
      arm_steps_(std::max(1L, std::lround(kArm_s / ts_s))),
      unfound_steps_(std::max(1L, std::lround(kUnfound_s / ts_s))) {}

void LockGuard::update(const EstimatorInput& in) {
  enc_theta_ = in.encoder_theta_e_rad;
  enc_omega_ = in.encoder_omega_e_rad_s;
  if (tripped_) return;  // the lost estimator is replaced at the re-arm; nothing to feed
  inner_->update(in);
  const EstimatorOutput o = inner_->output();
  const double err = half_turn_error_rad(o.theta_e_rad - enc_theta_);
  const double speed_err = std::fabs(o.omega_e_rad_s - enc_omega_);
  const bool beyond =
      std::fabs(err) > guard_rad_ || (guard_speed_rad_s_ > 0 && speed_err > guard_speed_rad_s_);
  // Armed once the estimator has found the rotor on its own: an EKF converging from its thesis
  // x0, HFI aligning after a start and an EEMF observer just taking over from its low-speed
  // source on a speed ramp cross the guard on their way in, and recover.
  const bool own = !inner_->aligning() && !inner_->on_fallback();
  if (!armed_) {
    within_ = beyond || !own ? 0 : within_ + 1;
    armed_ = within_ >= arm_steps_;
  }
  beyond_ = armed_ && beyond ? beyond_ + 1 : 0;
  // One that never held has not armed the angle guard; a speed far off the encoder's for longer
  // than any start takes is a lost one all the same. A fresh EEMF-RLS handed a 72 deg point
  // after a restart never found the rotor, braked at the current limit while the shaft ran up
  // from 700 rpm, and ended the thesis preset's sweep on over-speed.
  unfound_ = !armed_ && own && guard_speed_rad_s_ > 0 && speed_err > guard_speed_rad_s_ ? unfound_ + 1 : 0;
  // A current vector past the guard current is the other sign of a lost rotor: the frame turns
  // against the back-EMF faster than the current loops follow (it precedes the over-current trip).
  const bool surge = guard_current_A_ > 0 && std::hypot(in.ialpha_A, in.ibeta_A) > guard_current_A_;
  const bool slipped = armed_ && inner_->slipped();
  if (beyond_ >= guard_steps_ || unfound_ >= unfound_steps_ || surge || slipped) tripped_ = true;
}

void LockGuard::injection(double& ud_V, double& uq_V) const {
  if (tripped_) {
    ud_V = uq_V = 0;
    return;
  }
  inner_->injection(ud_V, uq_V);
}

void LockGuard::fundamental(double& id_A, double& iq_A) const {
  if (!tripped_) inner_->fundamental(id_A, iq_A);
}

EstimatorOutput LockGuard::output() const {
  EstimatorOutput o = inner_->output();
  if (tripped_) {
    o.theta_e_rad = enc_theta_;
    o.omega_e_rad_s = enc_omega_;
  }
  return o;
}

void LockGuard::rearm() {
  if (!tripped_) return;
  inner_ = make_();
  inner_->align(enc_theta_, enc_omega_);
  tripped_ = false;
  beyond_ = within_ = unfound_ = 0;
  armed_ = false;
}

}  // namespace synbench::emulator::firmware
