// The firmware side of the twin's register map: what each signal of the default profiles means
// on the twin's drives and meter (the structs' signals through drivers/device_signals.hpp, the
// control and status signals through a table of their own), plus what a drive does around its
// registers: the watchdog the profile names (counter: the heartbeat must change within
// timeout_ms while a drive is enabled; any_write: some write must arrive within it; else both
// drives stop in order and latch fault 6; none: no timer), the fault reset (on the level, or
// with a pulse-reset profile only on a rising edge, as a drive that wants a pulse does), and the
// measurement windows with their status and sequence numbers. The three devices share one
// trigger, as on the thesis bench: the first window start opens the twin's window on all of
// them, a start on another device while it is open joins it (same length), and each
// participant's results are published when it closes.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "drivers/devices.hpp"
#include "drivers/profile/device_profile.hpp"
#include "emulator/modbus/signal_provider.hpp"
#include "emulator/modbus/twin_instruments.hpp"
#include "emulator/twin.hpp"

namespace synbench::emulator {

class TwinSignals final : public SignalProvider {
 public:
  // The profiles give the heartbeat timeouts; their signals are served by RegisterServer.
  // std::invalid_argument naming the device and the signal when a profile maps a signal the
  // twin has no value for: a register that would read 0 whatever the plant does.
  TwinSignals(Twin& twin, const std::vector<drivers::DeviceProfile>& profiles);

  double read_signal(drivers::DeviceKind device, const drivers::ProfileSignal& s) override;
  // A window's batches (NaN past the last batch, and for a window without batches).
  double read_element(drivers::DeviceKind device, const drivers::ProfileSignal& s, std::size_t k) override;
  std::error_code write_signal(drivers::DeviceKind device, const drivers::ProfileSignal& s, double value) override;
  // With an any_write watchdog every accepted write restarts the device's timeout.
  void accepted_write(drivers::DeviceKind device) override;

  // Runs the twin `steps` periods, checking the watchdogs and the window every millisecond.
  void advance(std::int64_t steps);

  struct WindowState {
    int status = 0;  // 0 idle, 1 open, 2 done
    std::uint16_t sequence = 0;
  };
  WindowState window(drivers::DeviceKind device) const { return dev_[index(device)].window; }
  std::uint64_t watchdog_trips() const { return watchdog_trips_; }
  // The meter's totalizers and power meter (meter profiles "totalizer" and "power").
  TwinInstruments& instruments() { return instruments_; }
  // Overrides the profiles' heartbeat timeout of both drives (twin time). At a time scale X
  // the master's scheduling jitter counts X times over; a CI run at 20x may want a longer one.
  void set_watchdog_timeout_s(double timeout_s) {
    for (Device& d : dev_)
      if (d.timeout_s > 0) d.timeout_s = timeout_s;
  }

  // The structs the registers show: the firmware's telemetry and each device's last window.
  struct Served {
    drivers::SynrmTelemetry synrm;
    drivers::SynrmWindow synrm_window;
    drivers::LoadTelemetry load;
    drivers::LoadWindow load_window;
    drivers::MeterReading meter_window;
  };
  // Test hook: the registers show `fixed` instead (a round trip with chosen values); nullopt
  // goes back to the firmware's.
  void serve_fixed(std::optional<Served> fixed) { fixed_ = std::move(fixed); }

 private:
  struct Control;
  // The control or status signal of `device` that is no struct's member, or null.
  static const Control* find_control(drivers::DeviceKind device, std::string_view signal);
  // The engineering value of a signal, empty when the twin has none.
  std::optional<double> value(drivers::DeviceKind device, const drivers::ProfileSignal& s) const;
  // The values of an array signal (the last window's batches), empty when the twin has none.
  std::optional<std::vector<double>> array_values(drivers::DeviceKind device, const drivers::ProfileSignal& s) const;
  drivers::SynrmTelemetry synrm_telemetry() const;
  drivers::LoadTelemetry load_telemetry() const;

  struct Device {
    double heartbeat = 0;
    double heartbeat_change_s = 0;
    double timeout_s = 0;  // 0: no watchdog
    drivers::WatchdogKind watchdog = drivers::WatchdogKind::none;
    // A pulse-reset profile: the firmware resets on a rising edge of fault_reset only, and the
    // register holds the level written.
    bool reset_on_edge = false;
    double reset_level = 0;
    double window_length_ms = 1000;
    bool in_window = false;
    WindowState window;
  };
  static std::size_t index(drivers::DeviceKind k) { return static_cast<std::size_t>(k); }
  bool drive_enabled(drivers::DeviceKind k) const;
  // Whether a write of `v` to fault_reset resets the drive (and keeps the level it leaves).
  bool reset_requested(Device& d, double v);
  void check_watchdogs();
  void close_window();
  std::error_code start_window(drivers::DeviceKind k);

  Twin& twin_;
  std::array<Device, 3> dev_;
  std::uint64_t watchdog_trips_ = 0;
  bool window_active_ = false;
  double window_active_ms_ = 0;
  // Commands as last accepted (the firmware keeps some only as ramped references).
  double speed_set_rpm_ = 0, angle_set_deg_ = 0, torque_set_Nm_ = 0;
  drivers::Estimator estimator_ = drivers::Estimator::encoder;
  double f0_Hz_, kf_Hz_per_A_;  // the meter's calibration, used to turn counts into currents
  // Results of each device's last window (telemetry is the firmware's own).
  Served windows_;
  std::optional<Served> fixed_;
  TwinInstruments instruments_;
};

}  // namespace synbench::emulator
