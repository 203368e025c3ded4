// Limits, latched trips, ordered stop and E-stop.
#include "bench/safety_supervisor.hpp"

#include <cmath>
#include <cstdio>

#include "drivers/error.hpp"

namespace synbench::bench {
namespace {

std::string format(const char* fmt, double a, double b) {
  char buf[128];
  std::snprintf(buf, sizeof buf, fmt, a, b);
  return buf;
}

bool running(drivers::DriveState s) {
  return s == drivers::DriveState::running || s == drivers::DriveState::stopping;
}

}  // namespace

SafetySupervisor::SafetySupervisor(drivers::BenchDevices devices, SafetyLimits limits,
                                   EventSink sink)
    : dev_(devices), lim_(limits), sink_(std::move(sink)) {}

void SafetySupervisor::raise(double now_s, drivers::Fault fault, std::string detail) {
  if (trip_) return;  // the first cause is the one that counts
  trip_ = SafetyTrip{fault, std::move(detail), now_s};
  if (sink_)
    sink_("fault", std::string(drivers::fault_name(fault)) + ": " + trip_->detail);
  // Step one of the ordered stop: the load first, so the SynRM is never dragged by it.
  dev_.load->set_torque_Nm(0.0);
  phase_ = SafetyPhase::stopping_load;
  phase_since_s_ = now_s;
}

void SafetySupervisor::disable_all() {
  dev_.synrm->enable(false);
  dev_.load->enable(false);
}

void SafetySupervisor::estop(double now_s, const std::string& why) {
  disable_all();
  if (!trip_) {
    trip_ = SafetyTrip{drivers::Fault::estop, why, now_s};
    if (sink_) sink_("fault", "estop: " + why);
  }
  phase_ = SafetyPhase::estopped;
  phase_since_s_ = now_s;
  stop_duration_s_ = 0.0;
}

std::error_code SafetySupervisor::reset(double now_s) {
  if (phase_ == SafetyPhase::stopping_load || phase_ == SafetyPhase::stopping_speed)
    return make_error_code(errc::busy);
  if (auto ec = dev_.synrm->reset_fault()) return ec;
  if (auto ec = dev_.load->reset_fault()) return ec;
  if (trip_ && sink_) sink_("state", "reset after " + std::string(drivers::fault_name(trip_->fault)));
  trip_.reset();
  stop_duration_s_.reset();
  phase_ = SafetyPhase::normal;
  phase_since_s_ = now_s;
  return {};
}

void SafetySupervisor::tick(double now_s) {
  drivers::SynrmTelemetry st;
  drivers::LoadTelemetry lt;
  const std::error_code ec_s = dev_.synrm->read(st);
  const std::error_code ec_l = dev_.load->read(lt);
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
          format("no telemetry for %.2f s (limit %.2f s)", now_s - last_good_read_s_, lim_.link_timeout_s));
  }

  if (synrm_ && !trip_) {
    const auto& s = *synrm_;
    if (s.fault != drivers::Fault::none)
      raise(now_s, s.fault, "SynRM drive reports its own trip");
    else if (std::fabs(s.speed_rpm) > lim_.max_speed_rpm)
      raise(now_s, drivers::Fault::overspeed, format("speed %.0f rpm > %.0f rpm", std::fabs(s.speed_rpm), lim_.max_speed_rpm));
    else if (s.im_A > lim_.max_current_A)
      raise(now_s, drivers::Fault::overcurrent, format("current %.2f A > %.2f A", s.im_A, lim_.max_current_A));
    else if (s.udc_V > lim_.max_udc_V)
      raise(now_s, drivers::Fault::overvoltage, format("DC bus %.0f V > %.0f V", s.udc_V, lim_.max_udc_V));
    else if (running(s.state) && s.udc_V < lim_.min_udc_V)
      raise(now_s, drivers::Fault::undervoltage, format("DC bus %.0f V < %.0f V", s.udc_V, lim_.min_udc_V));
    else if (s.temp_C > lim_.max_temp_C)
      raise(now_s, drivers::Fault::overtemperature, format("winding %.1f degC > %.1f degC", s.temp_C, lim_.max_temp_C));
  }
  if (load_ && !trip_ && load_->fault != drivers::Fault::none)
    raise(now_s, drivers::Fault::load_drive, "load drive reports " + std::string(drivers::fault_name(load_->fault)));

  advance_stop(now_s);
}

void SafetySupervisor::advance_stop(double now_s) {
  const double in_phase = now_s - phase_since_s_;
  switch (phase_) {
    case SafetyPhase::stopping_load: {
      dev_.load->set_torque_Nm(0.0);
      const bool load_gone = load_ && std::fabs(load_->torque_Nm) < 0.05;
      if (load_gone || in_phase > lim_.stop_load_timeout_s) {
        // A load that did not let go is switched off before the speed comes down.
        if (!load_gone) dev_.load->enable(false);
        dev_.synrm->set_speed_rpm(0.0);  // step two
        phase_ = SafetyPhase::stopping_speed;
        phase_since_s_ = now_s;
      }
      return;
    }
    case SafetyPhase::stopping_speed: {
      dev_.synrm->set_speed_rpm(0.0);
      const bool still = synrm_ && std::fabs(synrm_->speed_rpm) < lim_.stopped_speed_rpm;
      const bool already_off = synrm_ && !running(synrm_->state);
      if (still || already_off || in_phase > lim_.stop_speed_timeout_s) {
        disable_all();  // step three
        phase_ = SafetyPhase::stopped;
        phase_since_s_ = now_s;
        stop_duration_s_ = now_s - trip_->at_s;
        if (sink_) sink_("state", "ordered stop complete after " + std::to_string(*stop_duration_s_) + " s");
      }
      return;
    }
    case SafetyPhase::normal:
    case SafetyPhase::stopped:
    case SafetyPhase::estopped:
      return;
  }
}

}  // namespace synbench::bench
