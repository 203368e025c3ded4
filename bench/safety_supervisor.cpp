// Limits, latched trips, ordered stop and E-stop.
#include "bench/safety_supervisor.hpp"

#include <algorithm>
#include <cmath>

#include "drivers/error.hpp"
#include "drivers/printf_text.hpp"

namespace synbench::bench {
SafetyLimits stricter(const SafetyLimits& a, const SafetyLimits& b) {
  SafetyLimits l = a;
  l.max_speed_rpm = std::min(a.max_speed_rpm, b.max_speed_rpm);
  l.max_current_A = std::min(a.max_current_A, b.max_current_A);
  l.max_udc_V = std::min(a.max_udc_V, b.max_udc_V);
  l.min_udc_V = std::max(a.min_udc_V, b.min_udc_V);
  l.max_temp_C = std::min(a.max_temp_C, b.max_temp_C);
  l.link_timeout_s = std::min(a.link_timeout_s, b.link_timeout_s);
  return l;
}

SafetySupervisor::SafetySupervisor(drivers::BenchDevices devices, SafetyLimits limits,
                                   EventSink sink)
    : dev_(devices), lim_(limits), sink_(std::move(sink)), plausibility_(limits.plausibility) {
  // The registers' steps decide which values can show a freeze (drivers/frozen_watch.hpp).
  if (dev_.synrm) plausibility_.set_resolution(dev_.synrm->resolution());
}

void SafetySupervisor::raise(double now_s, drivers::Fault fault, std::string detail,
                             std::optional<std::int64_t> fault_code_raw) {
  if (trip_) return;  // the first cause is the one that counts
  trip_ = SafetyTrip{fault, std::move(detail), now_s, fault_code_raw};
  if (sink_)
    sink_("fault", std::string(drivers::fault_name(fault)) + ": " + trip_->detail);
  // At once (the load drive's own ramp): a trip does not wait on a ramp.
  OrderedStopOptions opt;
  opt.load_timeout_s = lim_.stop_load_timeout_s;
  opt.stopped_speed_rpm = lim_.stopped_speed_rpm;
  opt.speed_timeout_s = lim_.stop_speed_timeout_s;
  stop_.begin(dev_, opt, now_s, load_ ? load_->torque_Nm : 0.0);
  phase_ = SafetyPhase::stopping_load;
}

namespace {

std::string failure(std::error_code ec, const std::string& detail) {
  return ec.message() + (detail.empty() ? "" : " (" + detail + ")");
}

// One disable request to one drive, its answer kept.
template <class Drive>
void send_disable(Drive& drive, DriveDisable& d, double now_s) {
  const std::error_code ec = drive.disable_once();
  ++d.attempts;
  d.last_sent_s = now_s;
  d.last_acknowledged = !ec;
  if (ec) {
    d.state = DisableState::repeating;
    d.error = "disable not acknowledged: " + failure(ec, drive.error_detail());
  } else if (d.state != DisableState::confirmed) {
    d.state = DisableState::acknowledged;
  }
}

}  // namespace

void SafetySupervisor::disable_all(double now_s) {
  // Both are always tried, each once: a failed SynRM disable must not keep the load's from
  // being sent, nor its repeats inside one call delay it. The repeats come every tick.
  report_ = DisableReport{};
  report_->at_s = now_s;
  send_disable(*dev_.synrm, report_->synrm, now_s);
  send_disable(*dev_.load, report_->load, now_s);
  // Each drive is given its documented stop time (an SS1-style ramp) on top of the read-back's.
  report_->synrm.deadline_s = now_s + lim_.stop_confirm_s + dev_.synrm->stop_time_s();
  report_->load.deadline_s = now_s + lim_.stop_confirm_s + dev_.load->stop_time_s();
  report_->synrm.first_acknowledged = report_->synrm.state == DisableState::acknowledged;
  report_->load.first_acknowledged = report_->load.state == DisableState::acknowledged;
  const auto tell = [this](const char* which, const DriveDisable& d) {
    if (sink_ && !d.first_acknowledged)
      sink_("fault", std::string("disabling the ") + which + " drive failed: " + d.error +
                         "; repeated every tick until it reads back disabled");
  };
  tell("SynRM", report_->synrm);
  tell("load", report_->load);
  // Right behind an acknowledged disable: an E-stop's own answer already says whether it took.
  zero_setpoints();
  confirming_ = true;
}

void SafetySupervisor::repeat_disables(double now_s) {
  if (!confirming_ || !report_) return;
  // A lost request goes out again every tick; one the drive acknowledged (it still reads running,
  // or cannot be read) at a bounded rate: repeating it every tick only loads the line.
  const auto due = [now_s](const DriveDisable& d) {
    return d.state == DisableState::repeating && (!d.last_acknowledged || now_s - d.last_sent_s >= kDisableRepeat_s - 1e-9);
  };
  if (due(report_->synrm)) send_disable(*dev_.synrm, report_->synrm, now_s);
  if (due(report_->load)) send_disable(*dev_.load, report_->load, now_s);
}

void SafetySupervisor::zero_setpoints() {
  if (!report_) return;
  // Only once the disable went through: a setpoint write never goes ahead of a disable.
  const auto through = [](const DriveDisable& d) { return d.state != DisableState::repeating && !d.setpoint_zeroed; };
  if (through(report_->synrm)) report_->synrm.setpoint_zeroed = !dev_.synrm->set_speed_rpm(0.0);
  if (through(report_->load)) report_->load.setpoint_zeroed = !dev_.load->set_torque_Nm(0.0);
}

void SafetySupervisor::estop(double now_s, const std::string& why) {
  stop_.cancel();
  disable_all(now_s);
  if (!trip_) {
    trip_ = SafetyTrip{drivers::Fault::estop, why, now_s, std::nullopt};
    if (sink_) sink_("fault", "estop: " + why);
  }
  phase_ = SafetyPhase::estopped;
  stop_duration_s_ = 0.0;
}

void SafetySupervisor::expect_stopped(double now_s) { disable_all(now_s); }

namespace {

// "the SynRM drive still reports running" / "... cannot be read"; empty when it reads stopped.
template <class Telemetry>
std::string not_stopped(const char* which, const std::optional<Telemetry>& t) {
  if (!t) return std::string("the ") + which + " drive cannot be read";
  if (drivers::running(t->state))
    return std::string("the ") + which + " drive still reports " + drivers::state_name(t->state);
  return {};
}

}  // namespace

std::string SafetySupervisor::unconfirmed() const {
  std::string s;
  for (const std::string& what : {not_stopped("SynRM", synrm_), not_stopped("load", load_)})
    if (!what.empty()) s += (s.empty() ? "" : " and ") + what;
  return s;
}

std::optional<double> SafetySupervisor::stop_deadline_s() const {
  if (!confirming_ || !report_) return std::nullopt;
  return std::max(report_->synrm.deadline_s, report_->load.deadline_s);
}

void SafetySupervisor::confirm_stop(double now_s) {
  if (!confirming_) return;
  const auto check = [&](const char* which, DriveDisable& d, bool read, std::optional<drivers::DriveState> state,
                         double stop_time_s, const std::string& read_error) {
    const bool runs = state && drivers::running(*state);
    if (read && !runs) {
      if (d.state == DisableState::confirmed) return;
      if (sink_ && (!d.first_acknowledged || d.attempts > 1))
        sink_("state", std::string("the ") + which + " drive reads back disabled after " + std::to_string(d.attempts) +
                           " disable requests");
      d.state = DisableState::confirmed;
      d.confirmed_s = now_s;
      d.error.clear();
      return;
    }
    // An acknowledged disable of a drive that ramps down on it (it reads stopping, or its
    // profile documents a stop time): its ramp is progress until its deadline; not repeated.
    if (read && d.last_acknowledged && now_s < d.deadline_s &&
        (*state == drivers::DriveState::stopping || stop_time_s > 0.0)) {
      d.state = DisableState::stopping;
      d.error = drivers::printf_text("reports %s within its stop time (%.2f s)", drivers::state_name(*state),
                                     d.deadline_s - report_->at_s);
      return;
    }
    // A disable lost on the link, or a drive that ignored it: repeated at the next tick's start,
    // also to a drive that cannot be read (a disable is harmless to repeat, and a flaky line may
    // carry it).
    d.state = DisableState::repeating;
    d.error = read ? std::string("still reports ") + drivers::state_name(*state) : "cannot be read back: " + read_error;
  };
  if (report_) {
    const auto state = [](const auto& t) { return t ? std::optional(t->state) : std::nullopt; };
    check("SynRM", report_->synrm, synrm_.has_value(), state(synrm_), dev_.synrm->stop_time_s(), synrm_read_error_);
    check("load", report_->load, load_.has_value(), state(load_), dev_.load->stop_time_s(), load_read_error_);
    zero_setpoints();
  }
  if (unconfirmed().empty()) {
    // Tried no longer than the stop is confirmed: once it is, the bench may be enabled again
    // with setpoints of its own.
    if (sink_ && report_ && !(report_->synrm.setpoint_zeroed && report_->load.setpoint_zeroed))
      sink_("fault", "the setpoints could not be written to zero after the disable (the drives read back disabled)");
    confirming_ = false;
    return;
  }
  if (alarm_ || !report_) return;
  // Only a drive past its own deadline raises the alarm; one still inside its stop time is named
  // with it when both are late.
  std::string late;
  const auto add_late = [&](const DriveDisable& d, const std::string& what, double stop_time_s) {
    if (what.empty() || now_s < d.deadline_s) return;
    late += (late.empty() ? "" : " and ") + what;
    if (stop_time_s > 0.0) late += drivers::printf_text(" (its stop time %.2f s)", stop_time_s);
  };
  add_late(report_->synrm, not_stopped("SynRM", synrm_), dev_.synrm->stop_time_s());
  add_late(report_->load, not_stopped("load", load_), dev_.load->stop_time_s());
  if (late.empty()) return;
  alarm_ = SafetyAlarm{late + drivers::printf_text(" %.2f s after the disable", now_s - report_->at_s), now_s};
  if (sink_) sink_("alarm", "ALARM: " + alarm_->detail + "; their own watchdogs are the second line");
}

std::error_code SafetySupervisor::reset() {
  if (stop_.active()) return make_error_code(errc::busy);
  if (alarm_ || confirming_) {
    // A reset must never hide a drive that did not stop.
    if (!unconfirmed().empty()) return make_error_code(errc::busy);
  }
  if (auto ec = dev_.synrm->reset_fault()) return ec;
  if (auto ec = dev_.load->reset_fault()) return ec;
  if (trip_ && sink_) sink_("state", "reset after " + std::string(drivers::fault_name(trip_->fault)));
  if (alarm_ && sink_) sink_("state", "alarm cleared: both drives read back stopped");
  trip_.reset();
  alarm_.reset();
  confirming_ = false;
  report_.reset();
  stop_duration_s_.reset();
  plausibility_.reset();
  phase_ = SafetyPhase::normal;
  return {};
}

void SafetySupervisor::tick(double now_s) {
  repeat_disables(now_s);
  drivers::SynrmTelemetry st;
  drivers::LoadTelemetry lt;
  const std::error_code ec_s = dev_.synrm->read(st);
  synrm_read_error_ = ec_s ? failure(ec_s, dev_.synrm->error_detail()) : std::string();
  const std::error_code ec_l = dev_.load->read(lt);
  load_read_error_ = ec_l ? failure(ec_l, dev_.load->error_detail()) : std::string();
  synrm_.reset();
  load_.reset();
  if (!ec_s) synrm_ = st;
  if (!ec_l) load_ = lt;
  if (!ec_s && !ec_l) {
    last_good_read_s_ = now_s;
    seen_good_read_ = true;
  } else if (!seen_good_read_) {
    last_good_read_s_ = now_s;  // the clock of a lost link starts at the first attempt
    seen_good_read_ = true;
  } else if (now_s - last_good_read_s_ > lim_.link_timeout_s) {
    // The drives' own watchdogs stop them; we still try the ordered stop.
    raise(now_s, drivers::Fault::link_loss,
          drivers::printf_text("no telemetry for %.2f s (limit %.2f s)", now_s - last_good_read_s_, lim_.link_timeout_s));
  }

  if (synrm_ && !trip_) {
    const auto& s = *synrm_;
    if (s.fault == drivers::Fault::unknown)
      raise(now_s, s.fault, "SynRM drive reports " + drivers::describe_fault(s.fault, s.fault_code_raw),
            s.fault_code_raw);
    else if (s.fault != drivers::Fault::none)
      raise(now_s, s.fault, "SynRM drive reports its own trip");
    else if (std::fabs(s.speed_rpm) > lim_.max_speed_rpm)
      raise(now_s, drivers::Fault::overspeed, drivers::printf_text("speed %.0f rpm > %.0f rpm", std::fabs(s.speed_rpm), lim_.max_speed_rpm));
    else if (s.im_A > lim_.max_current_A)
      raise(now_s, drivers::Fault::overcurrent, drivers::printf_text("current %.2f A > %.2f A", s.im_A, lim_.max_current_A));
    else if (s.udc_V > lim_.max_udc_V)
      raise(now_s, drivers::Fault::overvoltage, drivers::printf_text("DC bus %.0f V > %.0f V", s.udc_V, lim_.max_udc_V));
    else if (drivers::running(s.state) && s.udc_V < lim_.min_udc_V)
      raise(now_s, drivers::Fault::undervoltage, drivers::printf_text("DC bus %.0f V < %.0f V", s.udc_V, lim_.min_udc_V));
    else if (s.temp_C && *s.temp_C > lim_.max_temp_C)
      raise(now_s, drivers::Fault::overtemperature, drivers::printf_text("winding %.1f degC > %.1f degC", *s.temp_C, lim_.max_temp_C));
  }
  if (load_ && !trip_ && load_->fault != drivers::Fault::none)
    raise(now_s, drivers::Fault::load_drive, "load drive reports " + drivers::describe_fault(load_->fault, load_->fault_code_raw),
          load_->fault_code_raw);
  if (synrm_ && !trip_)
    if (const auto bad = plausibility_.check(now_s, *synrm_))
      raise(now_s, drivers::Fault::implausible_telemetry, "SynRM drive " + bad->describe());

  advance_stop(now_s);
  confirm_stop(now_s);
}

void SafetySupervisor::advance_stop(double now_s) {
  if (!stop_.active()) return;
  if (!stop_.tick(now_s, synrm_, load_)) {
    phase_ = stop_.step() == StopStep::load ? SafetyPhase::stopping_load : SafetyPhase::stopping_speed;
    return;
  }
  phase_ = SafetyPhase::stopped;
  stop_duration_s_ = now_s - trip_->at_s;
  expect_stopped(now_s);
  if (sink_) sink_("state", "ordered stop complete after " + std::to_string(*stop_duration_s_) + " s");
}

}  // namespace synbench::bench
