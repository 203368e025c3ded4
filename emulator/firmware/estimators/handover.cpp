// Low-speed handover between an EEMF observer and HFI or the encoder.
#include "emulator/firmware/estimators/handover.hpp"

#include <cmath>

namespace synbench::emulator::firmware {
namespace {

EstimatorOutput encoder_output(const EstimatorInput& in) {
  EstimatorOutput o;
  o.theta_e_rad = in.encoder_theta_e_rad;
  o.omega_e_rad_s = in.encoder_omega_e_rad_s;
  return o;
}

}  // namespace

LowSpeedHandover::LowSpeedHandover(std::unique_ptr<Estimator> main,
                                   std::unique_ptr<Estimator> fallback, double min_speed_rad_s,
                                   double hysteresis_rad_s, double ts_s,
                                   double speed_filter_s)
    : main_(std::move(main)), fallback_(std::move(fallback)), min_(min_speed_rad_s),
      hyst_(hysteresis_rad_s) {
  main_speed_.configure(speed_filter_s, ts_s);
  fallback_speed_.configure(speed_filter_s, ts_s);
}

void LowSpeedHandover::update(const EstimatorInput& in) {
  if (main_active_) {
    main_->update(in);
    const EstimatorOutput o = main_->output();
    fallback_speed_.reset(main_speed_.update(o.omega_e_rad_s));
    if (std::fabs(main_speed_.value()) < min_ - 2.0 * hyst_) {
      main_active_ = false;
      // The encoder as the fallback tells a genuinely slower shaft from an observer slipping at
      // its minimum speed, whose estimate falls while the shaft holds: handed to the encoder
      // unseen, such a point kept a position error sweeping the whole half turn, unflagged.
      if (!fallback_ && std::fabs(in.encoder_omega_e_rad_s) > min_ - hyst_) slipped_ = true;
      // The source from this very period on: what the fallback gave when it last ran is stale
      // by however long the observer held (one period's angle tens of degrees off, which the
      // window's position error counted as a slip).
      if (fallback_) {
        fallback_->align(o.theta_e_rad, o.omega_e_rad_s);
        fallback_out_ = fallback_->output();
      } else {
        fallback_out_ = encoder_output(in);
      }
    }
    return;
  }
  if (fallback_) {
    fallback_->update(in);
    fallback_out_ = fallback_->output();
  } else {
    fallback_out_ = encoder_output(in);
  }
  main_->update(in);
  main_->align(fallback_out_.theta_e_rad, fallback_out_.omega_e_rad_s);
  main_speed_.reset(fallback_speed_.update(fallback_out_.omega_e_rad_s));
  if (std::fabs(fallback_speed_.value()) > min_ - hyst_) main_active_ = true;
}

EstimatorOutput LowSpeedHandover::output() const {
  EstimatorOutput o = main_->output();  // parameter estimates come from the main estimator
  if (!main_active_) {
    o.theta_e_rad = fallback_out_.theta_e_rad;
    o.omega_e_rad_s = fallback_out_.omega_e_rad_s;
  }
  return o;
}

void LowSpeedHandover::injection(double& ud_V, double& uq_V) const {
  // The main estimator's excitation (PRBS) runs all the time so its identification stays
  // converged; the fallback's (HFI carrier) only while it is the source.
  main_->injection(ud_V, uq_V);
  if (!main_active_ && fallback_) {
    double d = 0, q = 0;
    fallback_->injection(d, q);
    ud_V += d;
    uq_V += q;
  }
}

void LowSpeedHandover::fundamental(double& id_A, double& iq_A) const {
  if (!main_active_ && fallback_) return fallback_->fundamental(id_A, iq_A);
  main_->fundamental(id_A, iq_A);
}

}  // namespace synbench::emulator::firmware
