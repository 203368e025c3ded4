// Lock guard [ours]: the bench has the encoder on the shaft anyway, as the reference for the
// estimator errors. Once a sensorless estimator has held within the guard angle of the encoder's
// (wrapped to (-90, 90] deg, so a SynRM's harmless half-turn ambiguity passes) for 50 ms on its
// own, the drive takes the angle and speed from the encoder when the estimated angle stays
// beyond the guard angle, or the estimated speed beyond the guard speed (an observer slipping by
// whole turns, whose wrapped angle error need not stay beyond), for the guard time, or at once
// on a current surge or when the estimator reports it slipped (Estimator::slipped), and reports
// it, until rearm() (the drive calls it once a changed speed or angle setpoint is reached). Before it has held (an EKF converging from its initial state, HFI
// aligning, an EEMF observer taking over on a speed ramp) only the surge counts: those cross the
// guard on their way in and recover.
// A slipped observer otherwise drives the current vector round a machine with ~170 V of
// back-EMF and trips on over-current (or runs away into over-speed), which latches and ends an
// unattended sweep; guarded, the point is flagged `lock_lost` and the sweep goes on
// (docs/estimators.md). Re-arming starts a fresh estimator, as an enable does, aligned to the
// encoder: what the lost one had learnt (an RLS memory, a tracking state) is what lost the
// rotor. While the guard holds, the lost estimator is neither fed nor injects.
#pragma once

#include <functional>
#include <memory>

#include "emulator/firmware/estimators/estimator.hpp"

namespace synbench::emulator::firmware {

class LockGuard final : public Estimator {
 public:
  using Factory = std::function<std::unique_ptr<Estimator>()>;
  // guard_rad, guard_speed_rad_s (electrical; 0: no speed check) for guard_s; guard_current_A
  // (0: no surge check).
  LockGuard(Factory make, double guard_rad, double guard_speed_rad_s, double guard_s,
            double guard_current_A, double ts_s);
  void update(const EstimatorInput& in) override;
  EstimatorOutput output() const override;
  void injection(double& ud_V, double& uq_V) const override;
  void fundamental(double& id_A, double& iq_A) const override;
  bool aligning() const override { return !tripped_ && inner_->aligning(); }
  bool on_fallback() const override { return !tripped_ && inner_->on_fallback(); }
  void align(double theta_e_rad, double omega_e_rad_s) override {
    inner_->align(theta_e_rad, omega_e_rad_s);
  }
  bool lock_lost() const override { return tripped_; }
  bool encoder_angle() const override { return tripped_ || inner_->encoder_angle(); }
  void rearm() override;

 private:
  Factory make_;
  std::unique_ptr<Estimator> inner_;
  double guard_rad_, guard_speed_rad_s_, guard_current_A_;
  long guard_steps_, arm_steps_, unfound_steps_;
  long beyond_ = 0;  // consecutive periods beyond the guard angle, once armed
  long within_ = 0;  // consecutive periods within it, before
  long unfound_ = 0;  // consecutive periods off the encoder's speed, before
  bool armed_ = false;
  bool tripped_ = false;
  double enc_theta_ = 0, enc_omega_ = 0;
};

}  // namespace synbench::emulator::firmware
