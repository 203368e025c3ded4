// The operating-point state machine and its runner.
#include "bench/point_procedure.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bench/current_angle.hpp"
#include "bench/window_plausibility.hpp"
#include "drivers/error.hpp"

namespace synbench::bench {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Failures of the link, not of the request: the same read may succeed on the next tick.
bool link_error(std::error_code ec) {
  return ec == errc::timeout || ec == errc::protocol || ec == errc::exception_reply || ec == errc::disconnected;
}

}  // namespace

PointProcedure::PointProcedure(drivers::BenchDevices devices, PointRequest request,
                               PointOptions options)
    : dev_(devices), req_(request), opt_(options), gate_(options.gate),
      load_ramp_(options.load_ramp_Nm_per_s) {
  record_.speed_rpm = req_.speed_rpm;
  record_.load_Nm = req_.load_Nm;
  record_.angle_deg = req_.angle_deg;
  record_.estimator = req_.estimator;
  record_.pwm = req_.pwm;
}

bool PointProcedure::check(std::error_code ec, const char* what) {
  if (!ec) return true;
  error_ = std::string(what) + ": " + ec.message();
  // The device's own words (signal, register, raw words) where it has them.
  if (!detail_.empty()) error_ += " (" + detail_ + ")";
  phase_ = PointPhase::failed;
  return false;
}

bool PointProcedure::tolerate(std::error_code ec, const char* what, double now_s, double since_s) {
  if (link_error(ec) && now_s - since_s <= opt_.telemetry_timeout_s) {
    ++tolerated_reads_;
    return true;
  }
  char buf[96];
  std::snprintf(buf, sizeof buf, " (nothing read for %.2f s)", now_s - since_s);
  check(ec, what);
  if (link_error(ec)) error_ += buf;
  return false;
}

bool PointProcedure::command(std::error_code ec, const char* what, double now_s, double& failing_since_s) {
  if (!ec) return true;
  if (failing_since_s < 0) failing_since_s = now_s;
  detail_.clear();
  tolerate(ec, what, now_s, failing_since_s);
  return false;
}

void PointProcedure::enter(PointPhase p, double now_s) {
  phase_ = p;
  t_phase_ = now_s;
  t_step_failing_ = -1;
}

void PointProcedure::begin_stop(double now_s, bool ramped) {
  // After a measured point the load comes off at the bench's ramp, as between points (a
  // sensorless drive at a high current angle must follow the acceleration); after a fault at
  // once (the load drive's own ramp): a faulted stop must not wait on the bench's ticks.
  OrderedStopOptions o;
  o.load_ramp_Nm_per_s = ramped ? opt_.load_ramp_Nm_per_s : 0.0;
  o.stopped_speed_rpm = opt_.stop_speed_rpm;
  o.speed_timeout_s = opt_.stop_timeout_s;
  stop_ramped_ = o.load_ramp_Nm_per_s > 0;
  const double from_Nm = load_ramp_.command();
  load_ramp_.start(0.0, 0.0);  // the stop moves the load from here on
  load_pending_ = false;
  stop_.begin(dev_, o, now_s, from_Nm);
  enter(PointPhase::stop, now_s);
}

void PointProcedure::open_window(double now_s) {
  if (!command(dev_.trigger->open_window(req_.window_s), "opening the measurement window", now_s, t_step_failing_))
    return;
  t_window_ = now_s;
  record_.settle_s = now_s - t_start_;
  enter(PointPhase::measure, now_s);
}

void PointProcedure::command_load(double target_Nm) {
  load_ramp_.retarget(target_Nm);
  load_pending_ = true;
}

bool PointProcedure::ramp_load(double now_s) {
  const double dt = t_last_tick_ < 0 ? 0.0 : now_s - t_last_tick_;
  t_last_tick_ = now_s;
  if (!load_pending_) return true;
  const double cmd = load_ramp_.step(dt);
  // Pending until written: a write lost on the link is made again next tick (the ramp has moved
  // on meanwhile, at its rate).
  if (!command(dev_.load->set_torque_Nm(cmd), "setting load torque", now_s, t_ramp_failing_)) return false;
  t_ramp_failing_ = -1;
  load_pending_ = !load_ramp_.done();
  return true;
}

void PointProcedure::tick(double now_s) {
  if (finished()) return;
  drivers::SynrmTelemetry st;
  drivers::LoadTelemetry lt;
  if (t_last_read_ < 0) t_last_read_ = now_s;
  if (phase_ != PointPhase::start) {
    std::error_code ec = dev_.synrm->read(st);
    const char* what = "reading SynRM drive telemetry";
    detail_ = ec ? dev_.synrm->error_detail() : std::string();
    if (!ec) {
      ec = dev_.load->read(lt);
      what = "reading load drive telemetry";
      if (ec) detail_ = dev_.load->error_detail();
    }
    // A lost read skips the tick: nothing is decided on telemetry that did not arrive.
    if (ec) {
      tolerate(ec, what, now_s, t_last_read_);
      return;
    }
    t_last_read_ = now_s;
    const auto fault = st.fault != drivers::Fault::none ? st.fault : lt.fault;
    const auto fault_code_raw = st.fault != drivers::Fault::none ? st.fault_code_raw : lt.fault_code_raw;
    const bool ramping_off = phase_ == PointPhase::stop && stop_ramped_ && stop_.step() == StopStep::load;
    if (fault != drivers::Fault::none && (phase_ != PointPhase::stop || ramping_off)) {
      // A fault during the ramped stop of a measured point takes the load off at once too.
      if (phase_ != PointPhase::stop) {
        record_.fault = std::string(drivers::fault_name(fault));
        record_.fault_code_raw = fault_code_raw;
        error_ = "fault latched during the point: " + drivers::describe_fault(fault, fault_code_raw);
      }
      begin_stop(now_s, /*ramped=*/false);
      return;
    }
    if (!ramp_load(now_s) && phase_ != PointPhase::stop) return;
    // Until the window closes. A trip the drive still holds from the previous point (its guard
    // hands back once the new setpoints are reached) is not this point's: only a trip after the
    // drive was seen in lock, or one still held when the window opens, counts.
    if (!st.lock_lost) lock_seen_ = true;
    if (st.lock_lost && lock_seen_ && phase_ != PointPhase::stop) record_.lock_lost = true;
  }

  const auto step = [&](std::error_code ec, const char* what) { return command(ec, what, now_s, t_step_failing_); };
  switch (phase_) {
    case PointPhase::start: {
      t_start_ = now_s;
      if (const auto ec = dev_.synrm->read(st)) {
        detail_ = dev_.synrm->error_detail();
        tolerate(ec, "reading SynRM drive telemetry", now_s, t_last_read_);
        return;
      }
      t_last_read_ = now_s;
      if (st.fault != drivers::Fault::none) {
        error_ = "SynRM drive has a latched fault (" + drivers::describe_fault(st.fault, st.fault_code_raw) +
                 "); reset it first";
        phase_ = PointPhase::failed;
        return;
      }
      if (opt_.continue_running && st.state == drivers::DriveState::running) {
        // Retarget a running bench: everything at once (the load at its ramp, from the setpoint
        // in force), then let the gate judge.
        if (const auto ec = dev_.load->read(lt)) {
          detail_ = dev_.load->error_detail();
          tolerate(ec, "reading load drive telemetry", now_s, t_last_read_);
          return;
        }
        if (!step(dev_.synrm->set_pwm(req_.pwm), "selecting the PWM scheme")) return;
        if (!step(dev_.synrm->set_estimator(req_.estimator), "selecting the estimator")) return;
        if (!step(dev_.synrm->set_angle_deg(req_.angle_deg), "setting the current angle")) return;
        if (!step(dev_.synrm->set_speed_rpm(req_.speed_rpm), "setting the speed")) return;
        load_ramp_.start(lt.torque_Nm, lt.torque_Nm);
        command_load(req_.load_Nm);
        t_last_tick_ = now_s;
        enter(PointPhase::load_up, now_s);
        return;
      }
      if (!step(dev_.load->set_torque_Nm(0.0), "setting load torque")) return;
      if (!step(dev_.load->enable(true), "enabling the load drive")) return;
      if (!step(dev_.synrm->set_pwm(req_.pwm), "selecting the PWM scheme")) return;
      if (!step(dev_.synrm->set_estimator(req_.estimator), "selecting the estimator")) return;
      sensorless_start_ = req_.estimator != drivers::Estimator::encoder;
      angle_pending_ = sensorless_start_ && opt_.sensorless_start_angle_deg > 0 &&
                       req_.angle_deg > opt_.sensorless_start_angle_deg;
      const double start_angle = angle_pending_ ? opt_.sensorless_start_angle_deg : req_.angle_deg;
      if (!step(dev_.synrm->set_angle_deg(start_angle), "setting the current angle"))
        return;
      if (!step(dev_.synrm->set_speed_rpm(req_.speed_rpm), "setting the speed")) return;
      if (!step(dev_.synrm->enable(true), "enabling the SynRM drive")) return;
      enter(PointPhase::spin_up, now_s);
      return;
    }
    case PointPhase::spin_up: {
      const bool reached = std::fabs(st.speed_rpm - req_.speed_rpm) < opt_.speed_reached_band_rpm;
      if (sensorless_start_ && !early_load_ &&
          std::fabs(st.speed_rpm) >= opt_.sensorless_load_at_speed_fraction * std::fabs(req_.speed_rpm)) {
        command_load(req_.load_Nm);
        early_load_ = true;
      }
      if (reached || now_s - t_phase_ > opt_.spin_up_timeout_s) {
        if (!reached) record_.unstable = true;
        if (!early_load_) command_load(req_.load_Nm);
        enter(PointPhase::load_up, now_s);
      }
      return;
    }
    case PointPhase::load_up: {
      if (std::fabs(lt.torque_Nm - req_.load_Nm) < 0.02 * req_.load_Nm + 0.02 ||
          now_s - t_phase_ > opt_.spin_up_timeout_s) {
        if (angle_pending_) {
          // The point's own angle. A lock the guard lost on the way belongs to the start: the new
          // angle setpoint hands the rotor to a fresh estimator, and the point is judged from here.
          if (!step(dev_.synrm->set_angle_deg(req_.angle_deg), "setting the current angle")) return;
          angle_pending_ = false;
          record_.lock_lost = false;
          lock_seen_ = false;
        }
        gate_.reset();
        enter(PointPhase::settle, now_s);
      }
      return;
    }
    case PointPhase::settle: {
      gate_.add(now_s, st.speed_rpm, st.im_A, st.pac_W);
      const double lost_band = std::max(opt_.speed_lost_band_rel * std::fabs(req_.speed_rpm),
                                        opt_.speed_lost_band_min_rpm);
      if (std::fabs(st.speed_rpm - req_.speed_rpm) <= lost_band)
        t_off_speed_ = -1;
      else if (t_off_speed_ < 0)
        t_off_speed_ = now_s;
      speed_lost_ = t_off_speed_ >= 0 && now_s - t_off_speed_ >= opt_.speed_lost_s;
      // Steady far off the setpoint (a stalled shaft) is not settled.
      const bool settled = now_s - t_phase_ >= opt_.min_settle_s && gate_.steady() && t_off_speed_ < 0;
      const bool timed_out = now_s - t_phase_ > opt_.settle_timeout_s;
      if (speed_lost_) {
        record_.unstable = true;
        open_window(now_s);
        return;
      }
      if (record_.lock_lost) {
        // The estimator lost the rotor and the drive runs on the encoder until the next point:
        // there is no steady state of the estimator to wait for. Measured at once, flagged.
        open_window(now_s);
        return;
      }
      if (settled || timed_out) {
        if (timed_out && !settled) record_.unstable = true;
        if (opt_.thermal && !st.temp_C) {
          // Refused before a start where the profiles are known (app/plan_needs.hpp); a device
          // that stopped reporting it is not warmed blind either.
          error_ = "the thermal precondition needs the winding temperature, and the SynRM drive reports no temp_C";
          begin_stop(now_s, /*ramped=*/true);
          return;
        }
        if (opt_.thermal && std::fabs(*st.temp_C - opt_.thermal->target_C) > opt_.thermal->band_C) {
          if (t_thermal_ < 0) t_thermal_ = now_s;
          if (now_s - t_thermal_ <= opt_.thermal->timeout_s) {
            // Warm with load or cool unloaded, then come back and settle again.
            const bool cold = *st.temp_C < opt_.thermal->target_C;
            command_load(cold ? opt_.thermal->warmup_load_Nm : 0.0);
            enter(PointPhase::thermal, now_s);
            return;
          }
          record_.unstable = true;  // measured outside the thermal window after the timeout
        }
        open_window(now_s);
      }
      return;
    }
    case PointPhase::thermal: {
      // Inside the band with half a band of margin, so the window does not end outside it.
      const auto& th = *opt_.thermal;
      const bool inside = st.temp_C && std::fabs(*st.temp_C - th.target_C) < 0.5 * th.band_C;
      if (inside || now_s - t_thermal_ > th.timeout_s) {
        command_load(req_.load_Nm);
        enter(PointPhase::load_up, now_s);
      }
      return;
    }
    case PointPhase::measure: {
      if (!window_closed_) {
        // The results come on the next tick: its telemetry read (above) must find both drives
        // without a fault after the close, so a fault at the very end (a master frozen past it)
        // fails the point instead of yielding a record; under the supervisor, its tick comes in
        // between too.
        window_closed_ = dev_.trigger->window_closed();
        return;
      }
      if (t_results_due_ < 0) t_results_due_ = now_s;
      const char* what = "";
      if (const auto ec = read_results(what)) {
        // The window's results stay on the devices until the next start: read again next tick.
        tolerate(ec, what, now_s, t_results_due_);
        return;
      }
      if (!error_.empty()) {
        // An implausible result: nothing stored, the bench stopped as after a fault.
        begin_stop(now_s, /*ramped=*/false);
        return;
      }
      if (opt_.ordered_stop_after) {
        begin_stop(now_s, /*ramped=*/true);
      } else {
        enter(PointPhase::done, now_s);
      }
      return;
    }
    case PointPhase::stop:
      if (stop_.tick(now_s, st, lt)) phase_ = error_.empty() ? PointPhase::done : PointPhase::failed;
      return;
    case PointPhase::done:
    case PointPhase::failed:
      return;
  }
}

std::error_code PointProcedure::read_results(const char*& what) {
  drivers::SynrmWindow w;
  drivers::LoadWindow lw;
  drivers::MeterReading m;
  what = "reading the SynRM drive window";
  if (auto ec = dev_.synrm->read_window(w)) return detail_ = dev_.synrm->error_detail(), ec;
  what = "reading the load drive window";
  if (auto ec = dev_.load->read_window(lw)) return detail_ = dev_.load->error_detail(), ec;
  what = "reading the power meter";
  if (auto ec = dev_.meter->read(m)) return detail_ = dev_.meter->error_detail(), ec;
  if (w.fault != drivers::Fault::none) {
    // Latched during the window: whatever the averages say, the drive did not hold the point.
    record_.fault = std::string(drivers::fault_name(w.fault));
    record_.fault_code_raw = w.fault_code_raw;
    error_ = "fault latched during the window, point not stored: " + drivers::describe_fault(w.fault, w.fault_code_raw);
    return {};
  }
  if (const auto why = implausible_window(w, lw, m)) {
    error_ = "implausible window result, point not stored: " + *why;
    return {};
  }
  if (const auto why = window_timing_mismatch(w, lw, m, req_.window_s, opt_.host_window_jitter_s)) {
    error_ = "window timing, point not stored: " + *why;
    return {};
  }
  auto& r = record_;
  r.speed_meas_rpm = w.speed_meas_rpm;
  r.im_A = w.im_A;
  r.id_A = w.id_A;
  r.iq_A = w.iq_A;
  // The angle the drive ran at, from the same means (a host window's are of the polled telemetry).
  r.angle_meas_deg = current_angle_deg(w.id_A, w.iq_A);
  r.angle_off = angle_off(req_.angle_deg, w.id_A, w.iq_A);
  r.ud_V = w.ud_V;
  r.uq_V = w.uq_V;
  r.udc_V = w.udc_V;
  if (m.pdcm_W && m.pdcg_W) {
    // A power meter's own averages; the currents are what they imply at the window's U_dc.
    r.pdcm_W = *m.pdcm_W;
    r.pdcg_W = *m.pdcg_W;
    r.idcm_A = r.udc_V > 0 ? r.pdcm_W / r.udc_V : 0.0;
    r.idcg_A = r.udc_V > 0 ? r.pdcg_W / r.udc_V : 0.0;
  } else {
    r.idcm_A = m.idcm_A;
    r.idcg_A = m.idcg_A;
    r.pdcm_W = r.udc_V * m.idcm_A;
    r.pdcg_W = r.udc_V * m.idcg_A;
  }
  const double wm = w.speed_meas_rpm * 2.0 * kPi / 60.0;
  r.pm_W = lw.torque_Nm * wm + opt_.load_b1_Nms_per_rad * wm * wm;
  r.efficiency = r.pdcm_W > 0 ? r.pm_W / r.pdcm_W : 0.0;
  r.pos_err_min_deg = w.pos_err_min_deg;
  r.pos_err_mean_deg = w.pos_err_mean_deg;
  r.pos_err_max_deg = w.pos_err_max_deg;
  r.speed_err_rpm = w.speed_err_rpm;
  r.ld_est_H = w.ld_est_H;
  r.lq_est_H = w.lq_est_H;
  r.rs_est_ohm = w.rs_est_ohm;
  auto err_pct = [](const std::optional<double>& est, const std::optional<double>& ref) {
    return est && ref && *ref != 0 ? std::optional<double>(100.0 * (*est - *ref) / *ref) : std::nullopt;
  };
  r.ld_err_pct = err_pct(w.ld_est_H, w.ld_ref_H);
  r.lq_err_pct = err_pct(w.lq_est_H, w.lq_ref_H);
  r.rs_err_pct = err_pct(w.rs_est_ohm, w.rs_ref_ohm);
  r.temp_C = w.temp_C;
  r.window_s = m.gate_s > 0 ? m.gate_s : w.window_s;
  r.samples = w.samples;
  r.window_source = w.keeper;
  r.voltage_limited = w.voltage_limited_fraction > 0;
  r.fallback_fraction = w.fallback_fraction;
  r.below_min_speed = w.fallback_fraction > 0.5;
  if (w.lock_lost_fraction > 0) r.lock_lost = true;
  if (const auto why = implausible_powers(r)) {
    error_ = "implausible window result, point not stored: " + *why;
    return {};
  }
  BudgetInputs in;
  in.udc_V = r.udc_V;
  in.idcm_A = r.idcm_A;
  in.idcg_A = r.idcg_A;
  in.torque_Nm = lw.torque_Nm;
  in.speed_rpm = w.speed_meas_rpm;
  in.im_A = w.im_A;
  in.pdcm_W = r.pdcm_W;
  in.pdcg_W = r.pdcg_W;
  in.pm_W = r.pm_W;
  in.load_b1_Nms_per_rad = opt_.load_b1_Nms_per_rad;
  in.window_s = w.window_s > 0 ? w.window_s : r.window_s;
  in.power_meter = m.pdcm_W && m.pdcg_W;
  in.synrm = &w;
  in.load = &lw;
  in.meter = &m;
  budget_ = point_budget(in, opt_.uncertainty);
  r.im_u_A = budget_->u(Output::im_A);
  r.im_u_repeat_A = budget_->u_repeat(Output::im_A);
  r.pdcm_u_W = budget_->u(Output::pdcm_W);
  r.pdcm_u_repeat_W = budget_->u_repeat(Output::pdcm_W);
  r.pdcg_u_W = budget_->u(Output::pdcg_W);
  r.pm_u_W = budget_->u(Output::pm_W);
  r.efficiency_u = budget_->u(Output::efficiency);
  r.efficiency_u_repeat = budget_->u_repeat(Output::efficiency);
  if (dev_.truth) r.truth = dev_.truth->read_truth_window();
  has_record_ = true;
  return {};
}

PointProcedure run_point(drivers::BenchDevices devices, drivers::Clock& clock,
                         const PointRequest& request, const PointOptions& options) {
  PointProcedure proc(devices, request, options);
  double next = clock.now_s();
  while (!proc.finished()) {
    proc.tick(clock.now_s());
    next += options.tick_s;
    clock.wait_until(next);
  }
  return proc;
}

}  // namespace synbench::bench
