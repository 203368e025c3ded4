// Signal values of the twin's firmware, the watchdog and the shared measurement window.
#include "emulator/modbus/twin_signals.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "drivers/error.hpp"

namespace synbench::emulator {

using drivers::DeviceKind;
using drivers::DriveState;

namespace {

// How often (in control periods) the watchdogs and the window are checked: 1 ms.
constexpr std::int64_t kCheckSteps = 10;

double code(DriveState s) { return static_cast<double>(static_cast<int>(s)); }
double code(drivers::Fault f) { return static_cast<double>(static_cast<int>(f)); }
double or0(const std::optional<double>& v) { return v.value_or(0.0); }

}  // namespace

TwinSignals::TwinSignals(Twin& twin, const std::vector<drivers::DeviceProfile>& profiles)
    : twin_(twin),
      f0_Hz_(twin.config().vfc.f0_Hz),
      kf_Hz_per_A_(twin.config().vfc.kf_Hz_per_A),
      instruments_(twin, profiles) {
  for (const drivers::DeviceProfile& p : profiles) {
    Device& d = dev_[index(p.kind)];
    d.watchdog = p.watchdog.kind;
    if (p.watchdog.kind != drivers::WatchdogKind::none) d.timeout_s = p.watchdog.timeout_ms / 1000.0;
    if (const drivers::ProfileSignal* r = p.find("fault_reset"))
      d.reset_on_edge = r->reset.mode == drivers::FaultResetMode::Mode::pulse;
  }
}

void TwinSignals::accepted_write(DeviceKind device) {
  Device& d = dev_[index(device)];
  if (d.watchdog == drivers::WatchdogKind::any_write) d.heartbeat_change_s = twin_.time_s();
}

bool TwinSignals::reset_requested(Device& d, double v) {
  if (!d.reset_on_edge) return v != 0;
  const bool rising = v != 0 && d.reset_level == 0;
  d.reset_level = v;
  return rising;
}

bool TwinSignals::drive_enabled(DeviceKind k) const {
  if (k == DeviceKind::synrm_drive) return twin_.synrm_drive().state() == DriveState::running;
  if (k == DeviceKind::load_drive)
    return twin_.load_drive().telemetry().state == DriveState::running;
  return false;
}

double TwinSignals::synrm_value(const std::string& n) const {
  auto& fw = twin_.synrm_drive();
  const Device& d = dev_[index(DeviceKind::synrm_drive)];
  if (n == "enable") return fw.state() == DriveState::running || fw.state() == DriveState::stopping;
  if (n == "heartbeat") return d.heartbeat;
  if (n == "fault_reset") return d.reset_level;
  if (n == "window_length_ms") return d.window_length_ms;
  if (n == "speed_setpoint_rpm") return speed_set_rpm_;
  if (n == "angle_setpoint_deg") return angle_set_deg_;
  if (n == "pwm_scheme") return static_cast<double>(static_cast<int>(fw.pwm()));
  if (n == "estimator") return static_cast<double>(static_cast<int>(estimator_));
  if (n == "window_status") return d.window.status;
  if (n == "window_sequence") return d.window.sequence;
  const drivers::SynrmWindow& w = synrm_window_;
  if (n.rfind("window_", 0) == 0) {
    if (n == "window_samples") return w.samples;
    if (n == "window_fault_code") return code(w.fault);
    if (n == "window_s") return w.window_s;
    if (n == "window_speed_meas_rpm") return w.speed_meas_rpm;
    if (n == "window_im_A") return w.im_A;
    if (n == "window_id_A") return w.id_A;
    if (n == "window_iq_A") return w.iq_A;
    if (n == "window_ud_V") return w.ud_V;
    if (n == "window_uq_V") return w.uq_V;
    if (n == "window_udc_V") return w.udc_V;
    if (n == "window_temp_C") return or0(w.temp_C);
    if (n == "window_voltage_limited_fraction") return w.voltage_limited_fraction;
    if (n == "window_pos_err_min_deg") return or0(w.pos_err_min_deg);
    if (n == "window_pos_err_mean_deg") return or0(w.pos_err_mean_deg);
    if (n == "window_pos_err_max_deg") return or0(w.pos_err_max_deg);
    if (n == "window_speed_err_rpm") return or0(w.speed_err_rpm);
    if (n == "window_ld_est_H") return or0(w.ld_est_H);
    if (n == "window_lq_est_H") return or0(w.lq_est_H);
    if (n == "window_rs_est_ohm") return or0(w.rs_est_ohm);
    if (n == "window_fallback_fraction") return w.fallback_fraction;
    if (n == "window_lock_lost_fraction") return w.lock_lost_fraction;
    if (n == "window_estimates_present")
      return (w.pos_err_mean_deg ? 1 : 0) + (w.ld_est_H ? 2 : 0) + (w.lq_est_H ? 4 : 0) + (w.rs_est_ohm ? 8 : 0);
    return 0;
  }
  const drivers::SynrmTelemetry t = fw.telemetry();
  if (n == "state") return code(t.state);
  if (n == "fault_code") return code(t.fault);
  if (n == "speed_rpm") return t.speed_rpm;
  if (n == "im_A") return t.im_A;
  if (n == "id_A") return t.id_A;
  if (n == "iq_A") return t.iq_A;
  if (n == "ud_V") return t.ud_V;
  if (n == "uq_V") return t.uq_V;
  if (n == "udc_V") return t.udc_V;
  if (n == "pac_W") return t.pac_W;
  if (n == "temp_C") return or0(t.temp_C);
  if (n == "voltage_limited") return t.voltage_limited ? 1 : 0;
  if (n == "pos_err_deg") return or0(t.pos_err_deg);
  if (n == "lock_lost") return t.lock_lost ? 1 : 0;
  return 0;
}

double TwinSignals::load_value(const std::string& n) const {
  const Device& d = dev_[index(DeviceKind::load_drive)];
  const drivers::LoadTelemetry t = twin_.load_drive().telemetry();
  if (n == "enable") return t.state == DriveState::running || t.state == DriveState::stopping;
  if (n == "heartbeat") return d.heartbeat;
  if (n == "fault_reset") return d.reset_level;
  if (n == "window_length_ms") return d.window_length_ms;
  if (n == "torque_setpoint_Nm") return torque_set_Nm_;
  if (n == "state") return code(t.state);
  if (n == "fault_code") return code(t.fault);
  if (n == "torque_Nm") return t.torque_Nm;
  if (n == "iq_A") return t.iq_A;
  if (n == "window_status") return d.window.status;
  if (n == "window_sequence") return d.window.sequence;
  if (n == "window_samples") return load_window_.samples;
  if (n == "window_torque_Nm") return load_window_.torque_Nm;
  return 0;
}

double TwinSignals::meter_value(const std::string& n) const {
  const Device& d = dev_[index(DeviceKind::vfc_meter)];
  if (n == "gate_length_ms") return d.window_length_ms;
  if (n == "f0_Hz") return f0_Hz_;
  if (n == "kf_Hz_per_A") return kf_Hz_per_A_;
  if (n == "gate_status") return d.window.status;
  if (n == "gate_sequence") return d.window.sequence;
  const drivers::MeterReading& m = meter_window_;
  if (n == "counts_m") return static_cast<double>(m.counts_m);
  if (n == "counts_g") return static_cast<double>(m.counts_g);
  if (n == "gate_s") return m.gate_s;
  if (n == "idcm_A") return m.idcm_A;
  if (n == "idcg_A") return m.idcg_A;
  return 0;
}

double TwinSignals::read_signal(DeviceKind device, const drivers::ProfileSignal& s) {
  switch (device) {
    case DeviceKind::synrm_drive: return synrm_value(s.name);
    case DeviceKind::load_drive: return load_value(s.name);
    case DeviceKind::vfc_meter:
      if (const auto v = instruments_.value(twin_, s)) return *v;
      return meter_value(s.name);
  }
  return 0;
}

std::error_code TwinSignals::start_window(DeviceKind k) {
  Device& d = dev_[index(k)];
  if (window_active_) {
    // One trigger for all devices: join the open window, if it is the same window.
    if (d.in_window || d.window_length_ms != window_active_ms_) return make_error_code(errc::busy);
  } else {
    twin_.open_window(d.window_length_ms / 1000.0);
    window_active_ = true;
    window_active_ms_ = d.window_length_ms;
  }
  d.in_window = true;
  d.window.status = 1;
  return {};
}

void TwinSignals::close_window() {
  window_active_ = false;
  for (std::size_t i = 0; i < dev_.size(); ++i) {
    Device& d = dev_[i];
    if (!d.in_window) continue;
    switch (static_cast<DeviceKind>(i)) {
      case DeviceKind::synrm_drive: synrm_window_ = twin_.synrm_drive().window_result(); break;
      case DeviceKind::load_drive: load_window_ = twin_.load_drive().window_result(); break;
      case DeviceKind::vfc_meter: {
        meter_window_ = twin_.meter_reading();
        // The meter turns counts into currents with its own calibration registers.
        const double g = meter_window_.gate_s;
        if (g > 0) {
          meter_window_.idcm_A = (static_cast<double>(meter_window_.counts_m) / g - f0_Hz_) / kf_Hz_per_A_;
          meter_window_.idcg_A = (static_cast<double>(meter_window_.counts_g) / g - f0_Hz_) / kf_Hz_per_A_;
        }
        break;
      }
    }
    d.in_window = false;
    d.window.status = 2;
    d.window.sequence = static_cast<std::uint16_t>(d.window.sequence + 1);
  }
}

std::error_code TwinSignals::write_signal(DeviceKind device, const drivers::ProfileSignal& s, double v) {
  const std::string& n = s.name;
  Device& d = dev_[index(device)];
  const double now = twin_.time_s();
  if (s.role == drivers::SignalRole::heartbeat) {
    if (v != d.heartbeat) d.heartbeat_change_s = now;
    d.heartbeat = v;
    return {};
  }
  if (s.role == drivers::SignalRole::window_length) {
    if (!(v > 0)) return make_error_code(errc::invalid_argument);
    d.window_length_ms = v;
    return {};
  }
  if (s.role == drivers::SignalRole::window_start) return v != 0 ? start_window(device) : std::error_code{};

  auto& synrm = twin_.synrm_drive();
  auto& load = twin_.load_drive();
  switch (device) {
    case DeviceKind::synrm_drive:
      if (n == "enable") {
        const auto ec = synrm.enable(v != 0);
        if (!ec && v != 0) d.heartbeat_change_s = now;  // the watchdog counts from the enable
        return ec;
      }
      if (n == "fault_reset") return reset_requested(d, v) ? synrm.reset_fault() : std::error_code{};
      if (n == "speed_setpoint_rpm") {
        const auto ec = synrm.set_speed_rpm(v);
        if (!ec) speed_set_rpm_ = v;
        return ec;
      }
      if (n == "angle_setpoint_deg") {
        const auto ec = synrm.set_angle_deg(v);
        if (!ec) angle_set_deg_ = v;
        return ec;
      }
      if (n == "pwm_scheme") return synrm.set_pwm(static_cast<drivers::Pwm>(static_cast<int>(v)));
      if (n == "estimator") {
        const auto e = static_cast<drivers::Estimator>(static_cast<int>(v));
        const auto ec = synrm.set_estimator(e);
        if (!ec) estimator_ = e;
        return ec;
      }
      break;
    case DeviceKind::load_drive:
      if (n == "enable") {
        const auto ec = load.enable(v != 0);
        if (!ec && v != 0) d.heartbeat_change_s = now;
        return ec;
      }
      if (n == "fault_reset") return reset_requested(d, v) ? load.reset_fault() : std::error_code{};
      if (n == "torque_setpoint_Nm") {
        const auto ec = load.set_torque_Nm(v);
        if (!ec) torque_set_Nm_ = v;
        return ec;
      }
      break;
    case DeviceKind::vfc_meter:
      if (n == "f0_Hz") {
        f0_Hz_ = v;
        return {};
      }
      if (n == "kf_Hz_per_A") {
        if (v == 0) return make_error_code(errc::invalid_argument);
        kf_Hz_per_A_ = v;
        return {};
      }
      break;
  }
  return make_error_code(errc::not_supported);
}

void TwinSignals::check_watchdogs() {
  const double now = twin_.time_s();
  for (const DeviceKind k : {DeviceKind::synrm_drive, DeviceKind::load_drive}) {
    Device& d = dev_[index(k)];
    if (d.timeout_s <= 0) continue;
    if (!drive_enabled(k)) {
      d.heartbeat_change_s = now;  // the timeout runs only while the drive is enabled
      continue;
    }
    if (now - d.heartbeat_change_s > d.timeout_s) {
      // Either drive losing its master stops both machines: each firmware ramps its own
      // command to zero, then latches fault 6 until the bench resets it.
      twin_.synrm_drive().stop_and_latch(drivers::Fault::watchdog);
      twin_.load_drive().stop_and_latch(drivers::Fault::watchdog);
      ++watchdog_trips_;
      for (Device& o : dev_) o.heartbeat_change_s = now;
    }
  }
}

void TwinSignals::advance(std::int64_t steps) {
  while (steps > 0) {
    const std::int64_t n = std::min(steps, kCheckSteps);
    twin_.run_steps(n);
    steps -= n;
    check_watchdogs();
    instruments_.update(twin_);
    if (window_active_ && !twin_.window_open()) close_window();
  }
}

}  // namespace synbench::emulator
