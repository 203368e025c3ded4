// Firmware of the PMSM load drive (physics.md 2, 7): torque control with i_dG = 0 on the
// encoder. The braking torque magnitude is ramped to its setpoint and turned into an i_q
// reference; the drive applies it against the direction of rotation. Its current loop is
// modelled by its closed-loop response (LoadModel); the window averages the measured torque.
#pragma once

#include <system_error>

#include "drivers/devices.hpp"
#include "emulator/firmware/pi.hpp"
#include "emulator/firmware/window_batches.hpp"
#include "emulator/firmware/window_stats.hpp"
#include "emulator/twin_config.hpp"

namespace synbench::emulator::firmware {

class LoadDriveFirmware {
 public:
  explicit LoadDriveFirmware(const TwinConfig& config);

  std::error_code enable(bool on);
  std::error_code set_torque_Nm(double torque_Nm);
  std::error_code reset_fault();
  void trip(drivers::Fault fault);
  // Ordered stop on the drive's own initiative (watchdog): ramps the torque to zero, then
  // latches `fault`.
  void stop_and_latch(drivers::Fault fault);
  // Fault hook: a wrong sign in the torque reference chain. While a non-zero torque is
  // commanded the drive motors the shaft with `torque_Nm` instead of braking; a zero command
  // (the ordered stop's first step) or a disable ends it.
  void inject_runaway(double torque_Nm) { runaway_Nm_ = torque_Nm; }

  // One PWM period: returns the current reference (braking magnitude, A).
  double control(double iq_measured_A);

  void begin_window(std::int64_t steps);
  drivers::LoadWindow window_result() const { return window_result_; }
  drivers::LoadTelemetry telemetry() const;
  double torque_command_Nm() const { return torque_cmd_Nm_; }
  double torque_constant_NmpA() const { return kt_; }

 private:
  TwinConfig cfg_;
  double ts_, kt_;
  drivers::DriveState state_ = drivers::DriveState::disabled;
  drivers::Fault fault_ = drivers::Fault::none;
  drivers::Fault pending_fault_ = drivers::Fault::none;
  double torque_set_Nm_ = 0, torque_cmd_Nm_ = 0, runaway_Nm_ = 0;
  LowPass f_iq_;
  std::int64_t window_left_ = 0;
  WindowStats w_iq_;
  WindowBatches b_iq_;
  drivers::LoadWindow window_result_;
};

}  // namespace synbench::emulator::firmware
