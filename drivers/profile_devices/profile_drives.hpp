// The typed devices of drivers/devices.hpp on any RegisterBus, from device profiles: the SynRM
// drive, the load drive and the VFC meter. Each maps its interface's calls to profile signals,
// keeps its watchdog heartbeat going when ticked, and exposes its measurement window to the
// trigger (ProfileWindowTrigger) that opens it on all devices at once.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <system_error>

#include "drivers/devices.hpp"
#include "drivers/profile_devices/heartbeat.hpp"
#include "drivers/profile_devices/host_window.hpp"
#include "drivers/profile_devices/signal_io.hpp"
#include "drivers/profile_devices/totalizer_window.hpp"
#include "drivers/profile_devices/window_channel.hpp"

namespace synbench::drivers {

// What the three profile devices share: the signals, the heartbeat and the window.
class ProfileDevice {
 public:
  ProfileDevice(RegisterBus& bus, DeviceProfile profile);
  virtual ~ProfileDevice() = default;
  ProfileDevice(const ProfileDevice&) = delete;
  ProfileDevice& operator=(const ProfileDevice&) = delete;

  const DeviceProfile& profile() const { return profile_; }
  SignalIo& io() { return io_; }
  WindowChannel& window() { return window_; }
  // What the trigger opens: the device's window channel, or the one set_window_source() gave.
  WindowSource& window_source() { return source_ ? *source_ : static_cast<WindowSource&>(window_); }
  // Sends the watchdog's refresh when due (unless `feed_watchdog` is false) and ends a reset
  // pulse whose time is up; errors are counted, the next tick retries.
  std::error_code tick(double now_s, bool feed_watchdog = true);
  // When tick() has something to do next (the watchdog's refresh counted only when fed).
  double next_heartbeat_s(bool feed_watchdog = true) const;
  std::uint64_t heartbeat_failures() const { return heartbeat_.failures(); }
  bool reset_pending() const { return reset_held_; }
  // What the last failed call ran into, in the device's terms (SignalIo::last_error).
  std::string device_error() const { return io_.last_error(); }

 protected:
  // Writes 1 to the fault-reset signal; with a pulse reset the next ticks write 0 after pulse_ms.
  std::error_code pulse_fault_reset();
  // A window kept other than by the device's window signals (host_window.hpp,
  // totalizer_window.hpp); the device's own constructor decides from its profile.
  void set_window_source(std::unique_ptr<WindowSource> source) { source_ = std::move(source); }
  // A host window over `plan` when the profile has poll_period_ms, else null.
  HostWindow* host_window_over(const ReadPlan& plan);

 private:
  DeviceProfile profile_;
  SignalIo io_;
  Heartbeat heartbeat_;
  WindowChannel window_;
  std::unique_ptr<WindowSource> source_;
  // A pulse reset's 1 is held: cleared at reset_clear_s_ (NaN: from the next tick's time).
  bool reset_held_ = false;
  double reset_clear_s_ = 0;
};

class ProfileSynrmDrive final : public SynrmDrive, public ProfileDevice {
 public:
  // `profile` must be of kind synrm_drive.
  ProfileSynrmDrive(RegisterBus& bus, DeviceProfile profile);

  std::error_code enable(bool on) override;
  std::error_code disable_once() override;
  std::error_code set_speed_rpm(double speed_rpm) override;
  std::error_code set_angle_deg(double angle_deg) override;
  // A profile without pwm_scheme (or estimator) accepts only the default (capwm, encoder): a
  // drive without the choice runs what it runs.
  std::error_code set_pwm(Pwm pwm) override;
  std::error_code set_estimator(Estimator estimator) override;
  std::error_code reset_fault() override;
  std::error_code read(SynrmTelemetry& out) override;
  std::error_code read_window(SynrmWindow& out) override;
  std::string error_detail() const override { return device_error(); }
  // From the profile's types and scales (drivers/frozen_watch.hpp).
  TelemetryResolution resolution() const override;
  double stop_time_s() const override { return profile().stop_time_ms * 1e-3; }

 private:
  std::error_code read_host_window(SynrmWindow& out);

  ReadPlan telemetry_, window_, estimator_window_;
  Estimator estimator_ = Estimator::encoder;  // estimator results are read only with another
  HostWindow* host_ = nullptr;  // a profile without window signals: the bench keeps the window
};

class ProfileLoadDrive final : public LoadDrive, public ProfileDevice {
 public:
  ProfileLoadDrive(RegisterBus& bus, DeviceProfile profile);

  std::error_code enable(bool on) override;
  std::error_code disable_once() override;
  std::error_code set_torque_Nm(double torque_Nm) override;
  std::error_code reset_fault() override;
  std::error_code read(LoadTelemetry& out) override;
  std::error_code read_window(LoadWindow& out) override;
  std::string error_detail() const override { return device_error(); }
  double stop_time_s() const override { return profile().stop_time_ms * 1e-3; }

 private:
  ReadPlan telemetry_, window_;
  HostWindow* host_ = nullptr;
};

class ProfileMeter final : public PowerMeter, public ProfileDevice {
 public:
  ProfileMeter(RegisterBus& bus, DeviceProfile profile);
  // The gate of the last window; errc::not_ready while it is open. By the profile's meter: the
  // device's gate, the counter differences of a totalizer, or a power meter's sampled average.
  std::error_code read(MeterReading& out) override;
  // The totalizer's window (meter totalizer), else null.
  const TotalizerWindow* totalizer() const { return totalizer_; }
  std::string error_detail() const override { return device_error(); }

 private:
  ReadPlan gate_, power_, calibration_;
  TotalizerWindow* totalizer_ = nullptr;
  HostWindow* host_ = nullptr;  // meter power
};

}  // namespace synbench::drivers
