// Firmware of the SynRM drive (physics.md 7): FOC with current loops every PWM period (40 Hz
// bandwidth, gains scheduled on the dynamic inductance, flux-map decoupling, dead-time
// compensation, SVM voltage limit with anti-windup), a 1 kHz speed loop (3 Hz) whose output is
// I_m with the operator's current angle, protection trips that latch, telemetry filters, and
// the measurement window accumulated at the control rate.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <vector>
#include <system_error>

#include "drivers/devices.hpp"
#include "emulator/firmware/estimators/estimator.hpp"
#include "emulator/firmware/pi.hpp"
#include "emulator/firmware/window_batches.hpp"
#include "emulator/firmware/window_stats.hpp"
#include "emulator/flux_map.hpp"
#include "emulator/inverter_model.hpp"
#include "emulator/mcidc.hpp"
#include "emulator/twin_config.hpp"

namespace synbench::emulator::firmware {

// What the drive's ADCs and encoder interface see at the start of a PWM period.
struct DriveSample {
  double ia_A = 0, ib_A = 0;      // measured phase currents (noisy, quantized)
  std::int64_t encoder_count = 0; // multi-turn encoder position
  double udc_V = 0;
  double temp_C = 0;
  std::optional<McidcSample> mcidc;  // phase-reluctance sample, when the estimator asks for it
};

// What the drive commands for the next PWM period.
struct DriveOutput {
  bool gates_on = false;
  double ualpha_V = 0, ubeta_V = 0;  // phase-voltage reference after limit and compensation
  Phases duty{0.5, 0.5, 0.5};
  drivers::Pwm pwm = drivers::Pwm::capwm;
  // CAPWM only: the modulator shifts one leg's pulse per period (a, b, c in turn; duty and edge
  // count unchanged) to open an active window long enough for an MCIDC slope, which centre-
  // aligned SVM lacks near 50 % duty, so an MCIDC estimator gets a sample every period
  // (docs/estimators.md).
  bool mcidc_window_shift = false;
};

class SynrmDriveFirmware {
 public:
  explicit SynrmDriveFirmware(const TwinConfig& config);

  std::error_code enable(bool on);
  std::error_code set_speed_rpm(double speed_rpm);
  std::error_code set_angle_deg(double angle_deg);
  std::error_code set_pwm(drivers::Pwm pwm);
  std::error_code set_estimator(drivers::Estimator estimator);
  std::error_code reset_fault();
  // Latches a fault raised outside the control loop (E-stop): gates off at once.
  void trip(drivers::Fault fault);
  // Ordered stop on the drive's own initiative (watchdog): ramps the speed to zero under control,
  // then gates off and latches `fault`. State `stopping` until then; commands are refused.
  void stop_and_latch(drivers::Fault fault);
  // The documented stop time of the drive's disable (FirmwareParams::stop_time_s).
  double stop_time_s() const;

  DriveOutput control(const DriveSample& sample);

  void begin_window(std::int64_t steps);
  bool window_open() const { return window_left_ > 0; }
  drivers::SynrmWindow window_result() const { return window_result_; }

  drivers::SynrmTelemetry telemetry() const;
  drivers::DriveState state() const { return state_; }
  drivers::Fault fault() const { return fault_; }
  drivers::Pwm pwm() const { return pwm_; }
  bool needs_mcidc() const { return needs_mcidc_; }
  double speed_reference_rpm() const { return speed_ref_rpm_; }

 private:
  void check_protection(const DriveSample& s, double ia, double ib, double speed_rpm);
  void gates_off();
  void rearm_guard();
  void accumulate(const DriveSample& s, double im, double id, double iq, bool limited,
                  double theta_enc, double speed_enc_rpm);

  TwinConfig cfg_;
  double ts_;
  int speed_divider_;
  int pole_pairs_;
  double counts_per_rev_;
  double adc_lsb_A_;
  FluxAxis flux_d_, flux_q_;
  double rs_nominal_ohm_;
  double dead_time_V_per_V_;  // dead-time voltage per volt of U_dc
  double speed_kp_ = 0, speed_ki_ = 0;

  drivers::DriveState state_ = drivers::DriveState::disabled;
  drivers::Fault fault_ = drivers::Fault::none;
  drivers::Fault pending_fault_ = drivers::Fault::none;  // latched when the ordered stop ends
  // cos and sin of angle_rad_, computed when it changes (angle_trig_rad_: the angle they are of).
  double angle_trig_rad_ = std::numeric_limits<double>::quiet_NaN(), angle_cos_ = 1.0, angle_sin_ = 0.0;
  // The end of a stop: the pending fault latched, or (a disable's ramp) disabled.
  void end_stop();
  drivers::Pwm pwm_;
  double speed_set_rpm_ = 0, speed_ref_rpm_ = 0, angle_rad_ = 0.0, angle_set_rad_ = 0.0;
  bool rearm_pending_ = false;  // a changed setpoint re-arms the lock guard once reached
  std::uint64_t step_ = 0;

  // Position source: the selected estimator, or the encoder when null.
  drivers::Estimator estimator_kind_ = drivers::Estimator::encoder;
  std::unique_ptr<Estimator> estimator_;
  bool needs_mcidc_ = false;
  bool guard_held_ = false;       // the lock guard held in the last period
  long guard_recovery_steps_ = 0; // zero current after a lock guard trip, then the speed loop
  // Voltages commanded one and two periods ago, without the dead-time compensation: the older
  // one acted during the last period.
  double u_hist_[2][2] = {{0, 0}, {0, 0}};

  // Encoder speed observer (tracking PLL on the mechanical angle).
  bool observer_init_ = false;
  double obs_theta_ = 0, obs_omega_ = 0, obs_kp_ = 0, obs_ki_ = 0;

  Pi speed_pi_, id_pi_, iq_pi_;
  double im_req_A_ = 0;
  double ud_ref_ = 0, uq_ref_ = 0, id_meas_ = 0, iq_meas_ = 0;
  bool limited_ = false;

  LowPass f_speed_, f_im_, f_id_, f_iq_, f_ud_, f_uq_, f_udc_, f_pac_, f_temp_;
  double limited_hold_s_ = 0;

  // Measurement window.
  std::int64_t window_left_ = 0, window_len_ = 0;
  std::int64_t window_count_start_ = 0;
  long window_limited_ = 0;
  long window_fallback_ = 0;  // samples on the estimator's low-speed fallback
  long window_lock_lost_ = 0; // samples on the encoder after a lock guard trip
  double pos_err_deg_ = 0;    // estimated minus encoder angle, last period, (-90, 90] deg
  drivers::Fault window_fault_ = drivers::Fault::none;
  WindowStats w_im_, w_id_, w_iq_, w_ud_, w_uq_, w_udc_, w_temp_;
  WindowStats w_pos_err_, w_speed_err_, w_ld_, w_lq_, w_rs_, w_id_enc_, w_iq_enc_;
  WindowBatches b_im_;
  std::vector<std::int64_t> batch_count_start_;  // encoder count at each batch's first sample
  drivers::SynrmWindow window_result_;
};

}  // namespace synbench::emulator::firmware
