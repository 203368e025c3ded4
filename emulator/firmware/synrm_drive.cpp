// SynRM drive firmware: FOC on the encoder, speed loop, protection, telemetry, window.
#include "emulator/firmware/synrm_drive.hpp"

#include <cmath>

#include "drivers/error.hpp"
#include "emulator/firmware/estimators/factory.hpp"

namespace synbench::emulator::firmware {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRpmPerRadS = 60.0 / (2.0 * kPi);
// An ordered stop ends (gates off) below this speed.
constexpr double kStoppedRpm = 20.0;
// Zero current after a lock guard trip [assumed]: several current-loop time constants (4 ms).
constexpr double kGuardRecovery_s = 0.02;

// [-pi, pi). Not estimator.hpp's wrap_pi: this one rounds a small angle through x + pi - pi, and
// the sweeps' lost-lock counts, chaotic in such last bits, are measured with it (switched, the
// thesis sweep's EEMF-LUT read 137 guarded points instead of 134, 2026-12-02).
double wrap_pi_drive(double x) {
  x = std::fmod(x + kPi, 2.0 * kPi);
  if (x < 0) x += 2.0 * kPi;
  return x - kPi;
}

// A position error in rad as deg in (-90, 90] (half_turn_error_rad).
double wrap_half_turn_deg(double err_rad) { return half_turn_error_rad(err_rad) * 180.0 / kPi; }

}  // namespace

SynrmDriveFirmware::SynrmDriveFirmware(const TwinConfig& config)
    : cfg_(config),
      ts_(config.step_s()),
      speed_divider_(static_cast<int>(std::lround(config.inverter.pwm_frequency_Hz /
                                                  config.firmware.speed_loop_rate_Hz))),
      pole_pairs_(config.synrm.pole_pairs),
      counts_per_rev_(std::ldexp(1.0, config.encoder.resolution_bits)),
      adc_lsb_A_(2.0 * config.firmware.adc_range_A / std::ldexp(1.0, config.firmware.adc_bits)),
      flux_d_(config.synrm.flux_d),
      flux_q_(config.synrm.flux_q),
      rs_nominal_ohm_(config.synrm.rs_ohm),
      dead_time_V_per_V_(config.inverter.dead_time_compensation
                             ? config.inverter.dead_time_s * config.inverter.pwm_frequency_Hz
                             : 0.0),
      pwm_(config.firmware.pwm) {
  const auto& f = cfg_.firmware;
  // Speed loop: crossover at the speed bandwidth for the bench inertia and the torque constant
  // at rated current and 45 deg (from the drive's own flux maps), PI zero a quarter below.
  const double i_rated = 2.26, c = std::sqrt(0.5) * i_rated;
  const double kt = 1.5 * pole_pairs_ * (flux_d_.psi(c) * c - flux_q_.psi(c) * c) / i_rated;
  const double ws = 2.0 * kPi * f.speed_bandwidth_Hz;
  speed_kp_ = config.total_inertia_kgm2() * ws / kt;
  speed_ki_ = speed_kp_ * ws / 4.0;
  speed_pi_.set_gains(speed_kp_, speed_ki_);
  speed_pi_.set_limits(-f.current_limit_A, f.current_limit_A);
  // Tracking observer: critically damped at its bandwidth.
  const double wo = 2.0 * kPi * f.speed_observer_bandwidth_Hz;
  obs_kp_ = 2.0 * wo;
  obs_ki_ = wo * wo;
  for (LowPass* lp : {&f_speed_, &f_im_, &f_id_, &f_iq_, &f_ud_, &f_uq_, &f_udc_, &f_pac_, &f_temp_})
    lp->configure(f.telemetry_filter_s, ts_);
  f_udc_.reset(config.dc_bus.source_V);
  f_temp_.reset(config.thermal.initial_C);
}

std::error_code SynrmDriveFirmware::enable(bool on) {
  if (!on) {
    const bool ramps = cfg_.firmware.disable_action == DisableAction::ramp;
    if (ramps && state_ == drivers::DriveState::running) {
      // An SS1-style drive: the disable ramps the speed to zero first (stopping), then the gates
      // go off and the drive reads disabled (control()).
      state_ = drivers::DriveState::stopping;
      pending_fault_ = drivers::Fault::none;
      speed_set_rpm_ = 0.0;
      return {};
    }
    if (ramps && state_ == drivers::DriveState::stopping && pending_fault_ == drivers::Fault::none)
      return {};  // already ramping down on an earlier disable
    // A disable from the master is obeyed at any time, also during the drive's own ordered
    // stop (as a safe torque off would be): the gates go off and that stop's fault latches.
    if (state_ == drivers::DriveState::stopping) end_stop();
    gates_off();
    if (state_ != drivers::DriveState::faulted) state_ = drivers::DriveState::disabled;
    return {};
  }
  if (state_ == drivers::DriveState::stopping || state_ == drivers::DriveState::faulted)
    return make_error_code(errc::device_fault);
  if (state_ == drivers::DriveState::running) return {};
  state_ = drivers::DriveState::running;
  // A sensorless estimator starts afresh from its initial state on every enable: while the gates
  // were off it saw no current and drifted. (An EEMF observer then starts on its low-speed source,
  // which hands over at once, aligned, when the shaft still turns above the minimum speed.)
  if (estimator_) estimator_ = make_estimator(estimator_kind_, cfg_).estimator;
  rearm_pending_ = false;
  speed_ref_rpm_ = obs_omega_ * kRpmPerRadS;
  speed_pi_.reset();
  id_pi_.reset();
  iq_pi_.reset();
  return {};
}

std::error_code SynrmDriveFirmware::set_speed_rpm(double speed_rpm) {
  // While stopping the drive owns the speed: only the zero it is going to is accepted.
  if (state_ == drivers::DriveState::stopping)
    return speed_rpm == 0.0 ? std::error_code{} : make_error_code(errc::device_fault);
  if (!std::isfinite(speed_rpm) || std::fabs(speed_rpm) > cfg_.firmware.max_speed_rpm)
    return make_error_code(errc::invalid_argument);
  if (speed_rpm != speed_set_rpm_) rearm_guard();
  speed_set_rpm_ = speed_rpm;
  return {};
}

std::error_code SynrmDriveFirmware::set_angle_deg(double angle_deg) {
  if (!std::isfinite(angle_deg) || angle_deg <= 0.0 || angle_deg >= 90.0)
    return make_error_code(errc::invalid_argument);
  const double angle_rad = angle_deg * kPi / 180.0;
  if (angle_rad != angle_set_rad_) rearm_guard();
  angle_set_rad_ = angle_rad;
  if (state_ != drivers::DriveState::running) angle_rad_ = angle_set_rad_;
  return {};
}

void SynrmDriveFirmware::rearm_guard() {
  // A new operating point hands the angle back to the estimator after a lock guard trip. Only a
  // changed setpoint is one: an ordered stop writes zero speed every tick, and re-arming there
  // would hand a lost drive a fresh estimator every 10 ms while it decelerates. The hand-over
  // waits until the speed and angle references have reached the new setpoints (control()), and
  // concerns a trip held now: one on the way there is the new point's, held to the next.
  if (estimator_ && estimator_->lock_lost()) rearm_pending_ = true;
}

std::error_code SynrmDriveFirmware::set_pwm(drivers::Pwm pwm) {
  pwm_ = pwm;
  return {};
}

std::error_code SynrmDriveFirmware::set_estimator(drivers::Estimator estimator) {
  if (estimator == estimator_kind_) return {};
  // The position source changes only with the gates off: a running FOC would lose its angle.
  if (state_ == drivers::DriveState::running || state_ == drivers::DriveState::stopping)
    return make_error_code(errc::busy);
  auto choice = make_estimator(estimator, cfg_);
  if (choice.error) return choice.error;
  estimator_ = std::move(choice.estimator);
  needs_mcidc_ = choice.needs_mcidc;
  estimator_kind_ = estimator;
  return {};
}

std::error_code SynrmDriveFirmware::reset_fault() {
  if (state_ == drivers::DriveState::faulted) {
    state_ = drivers::DriveState::disabled;
    fault_ = drivers::Fault::none;
  }
  return {};
}

void SynrmDriveFirmware::trip(drivers::Fault fault) {
  if (state_ != drivers::DriveState::faulted) fault_ = fault;  // the first cause is kept
  state_ = drivers::DriveState::faulted;
  if (window_left_ > 0 && window_fault_ == drivers::Fault::none) window_fault_ = fault;
  gates_off();
}

double SynrmDriveFirmware::stop_time_s() const { return cfg_.firmware.stop_time_s(); }

void SynrmDriveFirmware::end_stop() {
  if (pending_fault_ != drivers::Fault::none) return trip(pending_fault_);
  gates_off();
  state_ = drivers::DriveState::disabled;  // a disable's ramp, not a fault's stop
}

void SynrmDriveFirmware::stop_and_latch(drivers::Fault fault) {
  if (state_ != drivers::DriveState::running) {
    if (state_ != drivers::DriveState::stopping) trip(fault);
    else if (pending_fault_ == drivers::Fault::none) pending_fault_ = fault;  // a disable's ramp goes on, latching
    return;
  }
  state_ = drivers::DriveState::stopping;
  pending_fault_ = fault;
  speed_set_rpm_ = 0.0;
}

void SynrmDriveFirmware::gates_off() {
  speed_pi_.reset();
  id_pi_.reset();
  iq_pi_.reset();
  im_req_A_ = 0;
  ud_ref_ = uq_ref_ = 0;
}

void SynrmDriveFirmware::check_protection(const DriveSample& s, double ia, double ib,
                                          double speed_rpm) {
  const auto& f = cfg_.firmware;
  const double ic = -ia - ib;
  const double i_peak = std::max({std::fabs(ia), std::fabs(ib), std::fabs(ic)});
  if (i_peak > f.overcurrent_trip_A) return trip(drivers::Fault::overcurrent);
  if (s.udc_V > f.overvoltage_trip_V) return trip(drivers::Fault::overvoltage);
  if (std::fabs(speed_rpm) > f.overspeed_trip_rpm) return trip(drivers::Fault::overspeed);
  if (s.temp_C > f.overtemp_trip_C) return trip(drivers::Fault::overtemperature);
  if ((state_ == drivers::DriveState::running || state_ == drivers::DriveState::stopping) &&
      s.udc_V < f.undervoltage_trip_V)
    return trip(drivers::Fault::undervoltage);
}

DriveOutput SynrmDriveFirmware::control(const DriveSample& s) {
  ++step_;
  // ADC: quantize the sampled phase currents.
  const double ia = std::round(s.ia_A / adc_lsb_A_) * adc_lsb_A_;
  const double ib = std::round(s.ib_A / adc_lsb_A_) * adc_lsb_A_;

  // Encoder speed observer on the mechanical angle.
  const double theta_m = static_cast<double>(s.encoder_count) * (2.0 * kPi / counts_per_rev_);
  if (!observer_init_) {
    obs_theta_ = theta_m;
    observer_init_ = true;
  }
  const double e = theta_m - obs_theta_;  // multi-turn: no wrap needed
  obs_omega_ += obs_ki_ * e * ts_;
  obs_theta_ += (obs_omega_ + obs_kp_ * e) * ts_;
  const double speed_rpm = obs_omega_ * kRpmPerRadS;

  check_protection(s, ia, ib, speed_rpm);

  const double theta_enc = wrap_pi_drive(pole_pairs_ * theta_m);
  const double i_alpha = ia, i_beta = (ia + 2.0 * ib) / kSqrt3;  // Clarke with ic = -ia - ib
  double theta_e = theta_enc, we = pole_pairs_ * obs_omega_;
  if (estimator_) {
    EstimatorInput in;
    in.ts_s = ts_;
    in.ialpha_A = i_alpha;
    in.ibeta_A = i_beta;
    in.ualpha_V = u_hist_[1][0];
    in.ubeta_V = u_hist_[1][1];
    in.encoder_theta_e_rad = theta_enc;
    in.encoder_omega_e_rad_s = pole_pairs_ * obs_omega_;
    if (s.mcidc) {
      in.mcidc_phase = s.mcidc->phase;
      in.mcidc_reluctance_per_H = s.mcidc->reluctance_per_H;
    }
    estimator_->update(in);
    const EstimatorOutput o = estimator_->output();
    theta_e = wrap_pi_drive(o.theta_e_rad);
    we = o.omega_e_rad_s;
    if (estimator_->lock_lost() && !guard_held_) {
      // The lock guard moved the frame onto the encoder's in one period, with the current off
      // its reference by amperes and the current loops' integrators holding tens of volts of
      // correction for the lost frame's wrong back-EMF: carried on, that drove the current into
      // the over-current trip. The drive lets the current down first (a SynRM has no magnet
      // to drive current through zero volts), then the speed loop resumes on the encoder.
      id_pi_.reset();
      iq_pi_.reset();
      guard_recovery_steps_ = std::lround(kGuardRecovery_s / ts_);
    }
    guard_held_ = estimator_->lock_lost();
  }
  const double speed_ctrl_rpm = we / pole_pairs_ * kRpmPerRadS;
  const double ca = std::cos(theta_e), sa = std::sin(theta_e);
  id_meas_ = ca * i_alpha + sa * i_beta;
  iq_meas_ = -sa * i_alpha + ca * i_beta;

  DriveOutput out;
  out.pwm = pwm_;
  limited_ = false;
  double u_est_alpha = 0, u_est_beta = 0;  // the estimators' view of the applied voltage
  if (state_ == drivers::DriveState::stopping && std::fabs(speed_rpm) < kStoppedRpm &&
      std::fabs(speed_ref_rpm_) < kStoppedRpm)
    end_stop();
  if (state_ == drivers::DriveState::running || state_ == drivers::DriveState::stopping) {
    // Speed loop at its own rate, on a ramped reference; held at zero current while the
    // estimator is still finding the rotor (the reference ramp waits with it).
    if (guard_recovery_steps_ > 0) --guard_recovery_steps_;
    if ((estimator_ && estimator_->aligning()) || guard_recovery_steps_ > 0) {
      speed_pi_.reset();
      im_req_A_ = 0;
    } else if (step_ % static_cast<std::uint64_t>(speed_divider_) == 0) {
      const double dt = ts_ * speed_divider_;
      const double max_step = cfg_.firmware.speed_ramp_rpm_per_s * dt;
      speed_ref_rpm_ += std::clamp(speed_set_rpm_ - speed_ref_rpm_, -max_step, max_step);
      // Conditional integration while the voltage limit holds: the current loops cannot give
      // more current, so integrating the speed error further only winds the reference up to the
      // current limit; when the load then comes off (the ordered stop), that stored torque
      // drove a 1158 rpm shaft past 1650 rpm, the overspeed trip. An error that would take the
      // reference back out of the limit still integrates.
      const double speed_error = (speed_ref_rpm_ - speed_ctrl_rpm) / kRpmPerRadS;
      const bool winding_up = limited_hold_s_ > 0 && speed_error * im_req_A_ > 0;
      im_req_A_ = speed_pi_.update(speed_error, dt, winding_up);
    }
    // Sensorless, the current angle moves at a limited rate [assumed]: a step of the current
    // vector's direction at full current (76 to 40 deg between chained sweep points) is the
    // largest disturbance an observer sees, and HFI lost its lock on it. With the encoder the
    // angle steps as commanded.
    const double slew_rad = cfg_.firmware.sensorless_angle_slew_deg_per_s * kPi / 180.0 * ts_;
    if (estimator_ && slew_rad > 0)
      angle_rad_ += std::clamp(angle_set_rad_ - angle_rad_, -slew_rad, slew_rad);
    else
      angle_rad_ = angle_set_rad_;
    if (rearm_pending_ && angle_rad_ == angle_set_rad_ && speed_ref_rpm_ == speed_set_rpm_) {
      // The new point's own angle and speed, not the old one's: a fresh estimator handed the
      // rotor at once after a lost 76 deg point met the next point's 40 deg with the current
      // still at 76 deg, where the shaft makes any angle error grow, and lost it again.
      if (estimator_) estimator_->rearm();
      rearm_pending_ = false;
    }
    // Motoring and braking both keep i_d positive; the sign of I_m goes to i_q (torque sign).
    if (angle_rad_ != angle_trig_rad_) {  // the angle moves only while it slews: a sincos per change
      angle_trig_rad_ = angle_rad_;
      angle_cos_ = std::cos(angle_rad_);
      angle_sin_ = std::sin(angle_rad_);
    }
    const double id_ref = std::fabs(im_req_A_) * angle_cos_;
    const double iq_ref = im_req_A_ * angle_sin_;
    const double wc = 2.0 * kPi * cfg_.firmware.current_bandwidth_Hz;
    id_pi_.set_gains(wc * flux_d_.dynamic_inductance_H(id_ref), wc * rs_nominal_ohm_);
    iq_pi_.set_gains(wc * flux_q_.dynamic_inductance_H(iq_ref), wc * rs_nominal_ohm_);
    const double u_max = InverterModel::voltage_limit_V(s.udc_V);
    id_pi_.set_limits(-u_max, u_max);
    iq_pi_.set_limits(-u_max, u_max);
    const bool hold = limited_hold_s_ > 0;
    // The loops regulate the fundamental: an injecting estimator removes its own response.
    double id_fb = id_meas_, iq_fb = iq_meas_, ud_inj = 0, uq_inj = 0;
    if (estimator_) {
      estimator_->fundamental(id_fb, iq_fb);
      estimator_->injection(ud_inj, uq_inj);
    }
    const double ud = id_pi_.update(id_ref - id_fb, ts_, hold) - we * flux_q_.psi(iq_ref) + ud_inj;
    const double uq = iq_pi_.update(iq_ref - iq_fb, ts_, hold) + we * flux_d_.psi(id_ref) + uq_inj;
    ud_ref_ = ud;
    uq_ref_ = uq;
    // Inverse Park at the angle the voltage will act at (one period of delay plus half a period).
    const double th_out = theta_e + 1.5 * we * ts_;
    const double co = std::cos(th_out), so = std::sin(th_out);
    double ualpha = co * ud - so * uq, ubeta = so * ud + co * uq;
    double comp_alpha = 0, comp_beta = 0;
    if (dead_time_V_per_V_ > 0) {
      // Compensate the dead-time error with the direction of the reference phase currents.
      const Phases iref = to_phases(co * id_ref - so * iq_ref, so * id_ref + co * iq_ref);
      Phases comp;
      for (int n = 0; n < 3; ++n)
        comp[n] = dead_time_V_per_V_ * s.udc_V *
                  std::clamp(iref[n] / cfg_.inverter.dead_time_current_band_A, -1.0, 1.0);
      to_alpha_beta(comp, comp_alpha, comp_beta);
      ualpha += comp_alpha;
      ubeta += comp_beta;
    }
    const double mag = std::hypot(ualpha, ubeta);
    if (mag > u_max) {
      ualpha *= u_max / mag;
      ubeta *= u_max / mag;
      limited_ = true;
    }
    limited_hold_s_ = limited_ ? 0.01 : std::max(0.0, limited_hold_s_ - ts_);
    out.gates_on = true;
    out.ualpha_V = ualpha;
    out.ubeta_V = ubeta;
    // What the estimators take as the applied voltage: the command without the dead-time
    // compensation, which only cancels the inverter's dead-time error (the phase voltage
    // the inverter is believed to produce). Feeding them the compensated command would
    // add the full dead-time voltage, U_dc t_d / T_pwm, to their voltage balance.
    u_est_alpha = ualpha - (limited_ ? comp_alpha * u_max / mag : comp_alpha);
    u_est_beta = ubeta - (limited_ ? comp_beta * u_max / mag : comp_beta);
    out.duty = InverterModel::duties(ualpha, ubeta, s.udc_V);
    // Centre-aligned SVM near 50 % duty leaves no active vector long enough for the DC-link
    // current slope, and an MCIDC-only EKF would run blind from standstill up to tens of volts.
    out.mcidc_window_shift = needs_mcidc_ && pwm_ == drivers::Pwm::capwm;
  }
  u_hist_[1][0] = u_hist_[0][0];
  u_hist_[1][1] = u_hist_[0][1];
  u_hist_[0][0] = u_est_alpha;
  u_hist_[0][1] = u_est_beta;

  const double im = std::hypot(id_meas_, iq_meas_);
  f_speed_.update(speed_rpm);
  f_im_.update(im);
  f_id_.update(id_meas_);
  f_iq_.update(iq_meas_);
  f_ud_.update(ud_ref_);
  f_uq_.update(uq_ref_);
  f_udc_.update(s.udc_V);
  f_pac_.update(1.5 * (ud_ref_ * id_meas_ + uq_ref_ * iq_meas_));
  f_temp_.update(s.temp_C);
  if (estimator_) pos_err_deg_ = wrap_half_turn_deg(theta_e - theta_enc);
  accumulate(s, im, id_meas_, iq_meas_, limited_, theta_e - theta_enc, speed_ctrl_rpm - speed_rpm);
  return out;
}

void SynrmDriveFirmware::begin_window(std::int64_t steps) {
  window_len_ = window_left_ = steps;
  window_count_start_ = -1;
  window_limited_ = 0;
  window_fallback_ = 0;
  window_lock_lost_ = 0;
  window_fault_ = state_ == drivers::DriveState::faulted ? fault_ : drivers::Fault::none;
  for (WindowStats* w : {&w_im_, &w_id_, &w_iq_, &w_ud_, &w_uq_, &w_udc_, &w_temp_, &w_pos_err_,
                         &w_speed_err_, &w_ld_, &w_lq_, &w_rs_, &w_id_enc_, &w_iq_enc_})
    w->reset();
  b_im_.reset(steps, cfg_.firmware.window_batches);
  batch_count_start_.clear();
}

void SynrmDriveFirmware::accumulate(const DriveSample& s, double im, double id, double iq,
                                    bool limited, double pos_err_rad, double speed_err_rpm) {
  if (window_left_ <= 0) return;
  if (window_count_start_ < 0) window_count_start_ = s.encoder_count;
  if (b_im_.at_batch_start()) batch_count_start_.push_back(s.encoder_count);
  w_im_.add(im);
  b_im_.add(im);
  w_id_.add(id);
  w_iq_.add(iq);
  w_ud_.add(ud_ref_);
  w_uq_.add(uq_ref_);
  w_udc_.add(s.udc_V);
  w_temp_.add(s.temp_C);
  window_limited_ += limited ? 1 : 0;
  if (estimator_) {
    // A SynRM is symmetric under 180 electrical degrees: the error is wrapped to (-90, 90].
    // References at the true operating point: the currents in the encoder's frame.
    const double c = std::cos(pos_err_rad), sn = std::sin(pos_err_rad);
    w_id_enc_.add(c * id - sn * iq);
    w_iq_enc_.add(sn * id + c * iq);
    const bool lost = estimator_->lock_lost();
    window_fallback_ += estimator_->on_fallback() ? 1 : 0;
    window_lock_lost_ += lost ? 1 : 0;
    // The estimator's fields from the samples it drove: on the lock guard and on an EEMF's
    // encoder fallback the angle is the encoder's (an error of exactly 0, which pulled the mean
    // of a point handed back for a third of its window a third toward zero), and on the guard
    // the estimates are the lost estimator's last ones (on the fallback the RLS goes on
    // identifying). A window wholly on them leaves the fields empty (null in the record).
    if (!estimator_->encoder_angle()) {
      w_pos_err_.add(wrap_half_turn_deg(pos_err_rad));
      w_speed_err_.add(speed_err_rpm);
    }
    if (!lost) {
      const EstimatorOutput o = estimator_->output();
      if (o.ld_H) w_ld_.add(*o.ld_H);
      if (o.lq_H) w_lq_.add(*o.lq_H);
      if (o.rs_ohm) w_rs_.add(*o.rs_ohm);
    }
  }
  if (--window_left_ > 0) return;
  drivers::SynrmWindow r;
  r.samples = static_cast<std::uint32_t>(w_im_.count());
  r.window_s = static_cast<double>(window_len_) * ts_;
  // Encoder counts from the first to the last sample span samples - 1 periods.
  const double span_s = static_cast<double>(r.samples > 1 ? r.samples - 1 : 1) * ts_;
  r.speed_meas_rpm = static_cast<double>(s.encoder_count - window_count_start_) / counts_per_rev_ /
                     span_s * 60.0;
  r.im_A = w_im_.mean();
  r.batch_im_A = b_im_.means();
  if (!r.batch_im_A.empty()) {
    // A batch's speed from the encoder counts between its first sample and the next batch's
    // (the last: the window's last sample), as the window's own.
    const std::int64_t len = b_im_.batch_length();
    for (std::size_t k = 0; k < batch_count_start_.size(); ++k) {
      const bool last = k + 1 == batch_count_start_.size();
      const std::int64_t end = last ? s.encoder_count : batch_count_start_[k + 1];
      const double periods = static_cast<double>(last ? (len > 1 ? len - 1 : 1) : len);
      r.batch_speed_meas_rpm.push_back(static_cast<double>(end - batch_count_start_[k]) /
                                       counts_per_rev_ / (periods * ts_) * 60.0);
    }
  }
  r.id_A = w_id_.mean();
  r.iq_A = w_iq_.mean();
  r.ud_V = w_ud_.mean();
  r.uq_V = w_uq_.mean();
  r.udc_V = w_udc_.mean();
  r.temp_C = w_temp_.mean();
  r.voltage_limited_fraction = static_cast<double>(window_limited_) / static_cast<double>(r.samples);
  r.fallback_fraction = static_cast<double>(window_fallback_) / static_cast<double>(r.samples);
  r.lock_lost_fraction = static_cast<double>(window_lock_lost_) / static_cast<double>(r.samples);
  r.fault = state_ == drivers::DriveState::faulted ? fault_ : window_fault_;
  if (estimator_ && w_pos_err_.count()) {
    r.pos_err_min_deg = w_pos_err_.min();
    r.pos_err_mean_deg = w_pos_err_.mean();
    r.pos_err_max_deg = w_pos_err_.max();
    r.speed_err_rpm = w_speed_err_.mean();
  }
  if (estimator_) {
    if (w_ld_.count()) r.ld_est_H = w_ld_.mean();
    if (w_lq_.count()) r.lq_est_H = w_lq_.mean();
    if (w_rs_.count()) r.rs_est_ohm = w_rs_.mean();
    // The estimators see incremental inductances (MCIDC slopes, RLS): the references are the
    // dynamic inductances of the drive's flux maps at the operating point, and Rs(T).
    const double id_true = std::fabs(w_id_enc_.mean()), iq_true = std::fabs(w_iq_enc_.mean());
    r.ld_ref_H = flux_d_.dynamic_inductance_H(id_true);
    r.lq_ref_H = flux_q_.dynamic_inductance_H(iq_true);
    r.rs_ref_ohm = rs_nominal_ohm_ * (1.0 + cfg_.synrm.rs_temp_coeff_per_K * (*r.temp_C - cfg_.synrm.rs_ref_temp_C));
  }
  window_result_ = r;
}

drivers::SynrmTelemetry SynrmDriveFirmware::telemetry() const {
  drivers::SynrmTelemetry t;
  t.speed_rpm = f_speed_.value();
  t.im_A = f_im_.value();
  t.id_A = f_id_.value();
  t.iq_A = f_iq_.value();
  t.ud_V = f_ud_.value();
  t.uq_V = f_uq_.value();
  t.udc_V = f_udc_.value();
  t.pac_W = f_pac_.value();
  t.temp_C = f_temp_.value();
  t.voltage_limited = limited_hold_s_ > 0;
  t.lock_lost = estimator_ && estimator_->lock_lost();
  // On the lock guard the angle is the encoder's: no estimator error to show.
  if (estimator_ && !t.lock_lost) t.pos_err_deg = pos_err_deg_;
  t.state = state_;
  t.fault = fault_;
  return t;
}

}  // namespace synbench::emulator::firmware
