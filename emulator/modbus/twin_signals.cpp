// Signal values of the twin's firmware, the watchdog and the shared measurement window.
#include "emulator/modbus/twin_signals.hpp"

#include <algorithm>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>

#include "drivers/device_signals.hpp"
#include "drivers/error.hpp"

namespace synbench::emulator {

using drivers::DeviceKind;
using drivers::DriveState;

namespace {

// How often (in control periods) the watchdogs and the window are checked: 1 ms.
constexpr std::int64_t kCheckSteps = 10;

constexpr unsigned bit(DeviceKind k) { return 1u << static_cast<unsigned>(k); }
constexpr unsigned kSynrm = bit(DeviceKind::synrm_drive), kLoad = bit(DeviceKind::load_drive),
                   kMeter = bit(DeviceKind::vfc_meter), kDrives = kSynrm | kLoad;

// A struct member's value as a register shows it: an empty optional reads 0.
template <class S, std::size_t N>
std::optional<double> field(const S& in, const drivers::SignalField<S> (&table)[N], std::string_view signal) {
  if (const auto* f = drivers::find_field(table, signal)) return drivers::number(in, f->member).value_or(0.0);
  return std::nullopt;
}

}  // namespace

// A signal that is no struct's member: a command's last accepted value, the watchdog's
// heartbeat, the window's length, start, status and sequence, the meter's calibration.
struct TwinSignals::Control {
  unsigned devices;  // bit(kind) of each device that has it
  std::string_view signal;
  double (*read)(const TwinSignals&, DeviceKind);
  std::error_code (*write)(TwinSignals&, DeviceKind, double);  // null: read only
};

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
    for (const drivers::ProfileSignal& s : p.signals) {
      if (s.count ? !array_values(p.kind, s) : !value(p.kind, s))
        throw std::invalid_argument(std::string(drivers::name(p.kind)) + " profile '" + p.name + "': signal " +
                                    s.name + ": the twin has no value for it");
      // An array of batches holds the twin's batches, all of them.
      if (s.count && s.count != twin.config().firmware.window_batches)
        throw std::invalid_argument(std::string(drivers::name(p.kind)) + " profile '" + p.name + "': signal " +
                                    s.name + ": count " + std::to_string(s.count) + ", but the twin keeps " +
                                    std::to_string(twin.config().firmware.window_batches) +
                                    " batches (firmware.window_batches)");
    }
  }
}

const TwinSignals::Control* TwinSignals::find_control(DeviceKind device, std::string_view signal) {
  using T = TwinSignals;
  using K = DeviceKind;
  const auto enabled = [](const T& t, K k) -> double {
    const DriveState s = k == K::synrm_drive ? t.twin_.synrm_drive().state() : t.twin_.load_drive().telemetry().state;
    return drivers::running(s) ? 1 : 0;
  };
  const auto enable = [](T& t, K k, double v) {
    const auto ec = k == K::synrm_drive ? t.twin_.synrm_drive().enable(v != 0) : t.twin_.load_drive().enable(v != 0);
    if (!ec && v != 0) t.dev_[index(k)].heartbeat_change_s = t.twin_.time_s();  // the watchdog counts from the enable
    return ec;
  };
  const auto reset_level = [](const T& t, K k) { return t.dev_[index(k)].reset_level; };
  const auto reset = [](T& t, K k, double v) {
    if (!t.reset_requested(t.dev_[index(k)], v)) return std::error_code{};
    return k == K::synrm_drive ? t.twin_.synrm_drive().reset_fault() : t.twin_.load_drive().reset_fault();
  };
  const auto heartbeat = [](const T& t, K k) { return t.dev_[index(k)].heartbeat; };
  const auto beat = [](T& t, K k, double v) {
    Device& d = t.dev_[index(k)];
    if (v != d.heartbeat) d.heartbeat_change_s = t.twin_.time_s();
    d.heartbeat = v;
    return std::error_code{};
  };
  const auto length = [](const T& t, K k) { return t.dev_[index(k)].window_length_ms; };
  const auto set_length = [](T& t, K k, double v) {
    if (!(v > 0)) return make_error_code(errc::invalid_argument);
    t.dev_[index(k)].window_length_ms = v;
    return std::error_code{};
  };
  // A start reads 0: the device clears it as it acts (RegisterServer never asks).
  const auto zero = [](const T&, K) { return 0.0; };
  const auto start = [](T& t, K k, double v) { return v != 0 ? t.start_window(k) : std::error_code{}; };
  const auto status = [](const T& t, K k) -> double { return t.dev_[index(k)].window.status; };
  const auto sequence = [](const T& t, K k) -> double { return t.dev_[index(k)].window.sequence; };
  static const Control kControls[] = {
      {kDrives, "enable", enabled, enable},
      {kDrives, "fault_reset", reset_level, reset},
      {kDrives, "heartbeat", heartbeat, beat},
      {kDrives, "window_length_ms", length, set_length},
      {kMeter, "gate_length_ms", length, set_length},
      {kDrives, "window_start", zero, start},
      {kMeter, "gate_start", zero, start},
      {kDrives, "window_status", status, nullptr},
      {kMeter, "gate_status", status, nullptr},
      {kDrives, "window_sequence", sequence, nullptr},
      {kMeter, "gate_sequence", sequence, nullptr},
      {kSynrm, "speed_setpoint_rpm", [](const T& t, K) { return t.speed_set_rpm_; },
       [](T& t, K, double v) {
         const auto ec = t.twin_.synrm_drive().set_speed_rpm(v);
         if (!ec) t.speed_set_rpm_ = v;
         return ec;
       }},
      {kSynrm, "angle_setpoint_deg", [](const T& t, K) { return t.angle_set_deg_; },
       [](T& t, K, double v) {
         const auto ec = t.twin_.synrm_drive().set_angle_deg(v);
         if (!ec) t.angle_set_deg_ = v;
         return ec;
       }},
      {kSynrm, "pwm_scheme", [](const T& t, K) { return static_cast<double>(static_cast<int>(t.twin_.synrm_drive().pwm())); },
       [](T& t, K, double v) { return t.twin_.synrm_drive().set_pwm(static_cast<drivers::Pwm>(static_cast<int>(v))); }},
      {kSynrm, "estimator", [](const T& t, K) { return static_cast<double>(static_cast<int>(t.estimator_)); },
       [](T& t, K, double v) {
         const auto e = static_cast<drivers::Estimator>(static_cast<int>(v));
         const auto ec = t.twin_.synrm_drive().set_estimator(e);
         if (!ec) t.estimator_ = e;
         return ec;
       }},
      {kSynrm, "window_estimates_present",
       [](const T& t, K) {
         return static_cast<double>(drivers::estimates_present(t.fixed_ ? t.fixed_->synrm_window : t.windows_.synrm_window));
       },
       nullptr},
      {kLoad, "torque_setpoint_Nm", [](const T& t, K) { return t.torque_set_Nm_; },
       [](T& t, K, double v) {
         const auto ec = t.twin_.load_drive().set_torque_Nm(v);
         if (!ec) t.torque_set_Nm_ = v;
         return ec;
       }},
      // The meter turns counts into currents with these (close_window).
      {kMeter, "f0_Hz", [](const T& t, K) { return t.f0_Hz_; },
       [](T& t, K, double v) {
         t.f0_Hz_ = v;
         return std::error_code{};
       }},
      {kMeter, "kf_Hz_per_A", [](const T& t, K) { return t.kf_Hz_per_A_; },
       [](T& t, K, double v) {
         if (v == 0) return make_error_code(errc::invalid_argument);
         t.kf_Hz_per_A_ = v;
         return std::error_code{};
       }},
  };
  for (const Control& c : kControls)
    if ((c.devices & bit(device)) && c.signal == signal) return &c;
  return nullptr;
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

drivers::SynrmTelemetry TwinSignals::synrm_telemetry() const {
  return fixed_ ? fixed_->synrm : twin_.synrm_drive().telemetry();
}

drivers::LoadTelemetry TwinSignals::load_telemetry() const {
  return fixed_ ? fixed_->load : twin_.load_drive().telemetry();
}

std::optional<double> TwinSignals::value(DeviceKind device, const drivers::ProfileSignal& s) const {
  if (const Control* c = find_control(device, s.name)) return c->read(*this, device);
  const Served& w = fixed_ ? *fixed_ : windows_;
  switch (device) {
    case DeviceKind::synrm_drive:
      if (drivers::find_field(drivers::kSynrmTelemetrySignals, s.name))
        return field(synrm_telemetry(), drivers::kSynrmTelemetrySignals, s.name);
      return field(w.synrm_window, drivers::kSynrmWindowSignals, s.name);
    case DeviceKind::load_drive:
      if (drivers::find_field(drivers::kLoadTelemetrySignals, s.name))
        return field(load_telemetry(), drivers::kLoadTelemetrySignals, s.name);
      return field(w.load_window, drivers::kLoadWindowSignals, s.name);
    case DeviceKind::vfc_meter:
      if (const auto v = instruments_.value(twin_, s)) return v;
      return field(w.meter_window, drivers::kMeterGateSignals, s.name);
  }
  return std::nullopt;
}

std::optional<std::vector<double>> TwinSignals::array_values(DeviceKind device, const drivers::ProfileSignal& s) const {
  const Served& w = fixed_ ? *fixed_ : windows_;
  const auto of = [&](const auto& in, const auto& table) -> std::optional<std::vector<double>> {
    if (const auto* f = drivers::find_array(table, s.name)) return drivers::numbers(in, f->member);
    return std::nullopt;
  };
  switch (device) {
    case DeviceKind::synrm_drive: return of(w.synrm_window, drivers::kSynrmWindowArrays);
    case DeviceKind::load_drive: return of(w.load_window, drivers::kLoadWindowArrays);
    case DeviceKind::vfc_meter: return of(w.meter_window, drivers::kMeterGateArrays);
  }
  return std::nullopt;
}

double TwinSignals::read_element(DeviceKind device, const drivers::ProfileSignal& s, std::size_t k) {
  const auto v = array_values(device, s);
  return v && k < v->size() ? (*v)[k] : std::numeric_limits<double>::quiet_NaN();
}

double TwinSignals::read_signal(DeviceKind device, const drivers::ProfileSignal& s) {
  return value(device, s).value_or(0.0);  // the constructor refused a profile with a signal it lacks
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
      case DeviceKind::synrm_drive: windows_.synrm_window = twin_.synrm_drive().window_result(); break;
      case DeviceKind::load_drive: windows_.load_window = twin_.load_drive().window_result(); break;
      case DeviceKind::vfc_meter: {
        drivers::MeterReading& m = windows_.meter_window;
        m = twin_.meter_reading();
        // The meter turns counts into currents with its own calibration registers.
        m.f0_Hz = f0_Hz_;
        m.kf_Hz_per_A = kf_Hz_per_A_;
        const double g = m.gate_s;
        if (g > 0) {
          m.idcm_A = (static_cast<double>(m.counts_m) / g - f0_Hz_) / kf_Hz_per_A_;
          m.idcg_A = (static_cast<double>(m.counts_g) / g - f0_Hz_) / kf_Hz_per_A_;
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
  const Control* c = find_control(device, s.name);
  return c && c->write ? c->write(*this, device, v) : make_error_code(errc::not_supported);
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
