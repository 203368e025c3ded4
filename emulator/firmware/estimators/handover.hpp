// Below its minimum speed an EEMF observer hands the angle to another source — HFI or the
// encoder — as the thesis did below 500 rpm; it keeps running aligned to that source, so it
// takes over without a jump when the speed rises again. It takes over a hysteresis below the
// minimum speed (so a point at the minimum speed runs on it) and hands back two below. The
// decisions look at speeds smoothed over `speed_filter_s`: an observer's reported speed carries
// its proportional path, tens of rpm of noise per sample that would flip the source back and
// forth (each flip re-aligns the observer).
// With the encoder as the fallback it also reports a slip: a hand-back with the shaft still
// above the take-over speed and the observer's angle off the shaft's; the lock guard trips on it.
#pragma once

#include <memory>

#include "emulator/firmware/estimators/estimator.hpp"
#include "emulator/firmware/pi.hpp"

namespace synbench::emulator::firmware {

class LowSpeedHandover final : public Estimator {
 public:
  // `fallback` null means the encoder. With the encoder, a hand-back while the shaft still
  // turns above the take-over speed and the observer's angle is more than `slip_angle_rad` off
  // the encoder's (wrapped to a half turn) is a slip (slipped()).
  LowSpeedHandover(std::unique_ptr<Estimator> main, std::unique_ptr<Estimator> fallback,
                   double min_speed_rad_s, double hysteresis_rad_s, double slip_angle_rad,
                   double ts_s, double speed_filter_s = 0.02);
  void update(const EstimatorInput& in) override;
  EstimatorOutput output() const override;
  void injection(double& ud_V, double& uq_V) const override;
  void fundamental(double& id_A, double& iq_A) const override;
  bool main_active() const { return main_active_; }
  bool on_fallback() const override { return !main_active_; }
  bool slipped() const override { return slipped_; }
  bool encoder_angle() const override { return !main_active_ && !fallback_; }
  bool aligning() const override { return !main_active_ && fallback_ && fallback_->aligning(); }

 private:
  std::unique_ptr<Estimator> main_, fallback_;
  double min_, hyst_, slip_angle_;
  LowPass main_speed_, fallback_speed_;
  bool main_active_ = false;
  bool slipped_ = false;
  EstimatorOutput fallback_out_;
};

}  // namespace synbench::emulator::firmware
