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
void send_disable(Drive& drive, DriveDisable& d) {
  const std::error_code ec = drive.disable_once();
  ++d.attempts;
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
  send_disable(*dev_.synrm, report_->synrm);
  send_disable(*dev_.load, report_->load);
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
  if (!confirm_deadline_s_) confirm_deadline_s_ = now_s + lim_.stop_confirm_s;
}

void SafetySupervisor::repeat_disables() {
  if (!confirm_deadline_s_ || !report_) return;
  if (report_->synrm.state == DisableState::repeating) send_disable(*dev_.synrm, report_->synrm);
  if (report_->load.state == DisableState::repeating) send_disable(*dev_.load, report_->load);
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

std::string SafetySupervisor::unconfirmed() const {
  std::string s;
  const auto add = [&s](const char* what) { s += (s.empty() ? "" : " and ") + std::string(what); };
  if (!synrm_) add("the SynRM drive cannot be read");
  else if (drivers::running(synrm_->state)) add("the SynRM drive still reports running");
  if (!load_) add("the load drive cannot be read");
  else if (drivers::running(load_->state)) add("the load drive still reports running");
  return s;
}

void SafetySupervisor::confirm_stop(double now_s) {
  if (!confirm_deadline_s_) return;
  const auto check = [&](const char* which, DriveDisable& d, bool read, bool runs, const std::string& read_error) {
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
    // A disable lost on the link, or a drive that ignored it: repeated at the next tick's start,
    // also to a drive that cannot be read (a disable is harmless to repeat, and a flaky line may
    // carry it).
    d.state = DisableState::repeating;
    d.error = read ? "still reports running" : "cannot be read back: " + read_error;
  };
  if (report_) {
    check("SynRM", report_->synrm, synrm_.has_value(), synrm_ && drivers::running(synrm_->state), synrm_read_error_);
    check("load", report_->load, load_.has_value(), load_ && drivers::running(load_->state), load_read_error_);
    zero_setpoints();
  }
  const std::string running = unconfirmed();
  if (running.empty()) {
    // Tried no longer than the stop is confirmed: once it is, the bench may be enabled again
    // with setpoints of its own.
    if (sink_ && report_ && !(report_->synrm.setpoint_zeroed && report_->load.setpoint_zeroed))
      sink_("fault", "the setpoints could not be written to zero after the disable (the drives read back disabled)");
    confirm_deadline_s_.reset();
    return;
  }
  if (alarm_ || now_s < *confirm_deadline_s_) return;
  char when[48];
  std::snprintf(when, sizeof when, " %.2f s after the disable", now_s - (*confirm_deadline_s_ - lim_.stop_confirm_s));
  alarm_ = SafetyAlarm{running + when, now_s};
  if (sink_) sink_("alarm", "ALARM: " + alarm_->detail + "; their own watchdogs are the second line");
}

std::error_code SafetySupervisor::reset() {
  if (stop_.active()) return make_error_code(errc::busy);
  if (alarm_ || confirm_deadline_s_) {
    // A reset must never hide a drive that did not stop.
    if (!unconfirmed().empty()) return make_error_code(errc::busy);
  }
  if (auto ec = dev_.synrm->reset_fault()) return ec;
  if (auto ec = dev_.load->reset_fault()) return ec;
  if (trip_ && sink_) sink_("state", "reset after " + std::string(drivers::fault_name(trip_->fault)));
  if (alarm_ && sink_) sink_("state", "alarm cleared: both drives read back stopped");
  trip_.reset();
  alarm_.reset();
  confirm_deadline_s_.reset();
  report_.reset();
  stop_duration_s_.reset();
  plausibility_.reset();
  phase_ = SafetyPhase::normal;
  return {};
}

void SafetySupervisor::tick(double now_s) {
  repeat_disables();
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
