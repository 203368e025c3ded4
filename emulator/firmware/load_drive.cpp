// PMSM load drive firmware: ramped torque control, protection latch, window.
#include "emulator/firmware/load_drive.hpp"

#include <algorithm>
#include <cmath>

#include "drivers/error.hpp"

namespace synbench::emulator::firmware {

LoadDriveFirmware::LoadDriveFirmware(const TwinConfig& config)
    : cfg_(config), ts_(config.step_s()),
      kt_(1.5 * config.load.pole_pairs * config.load.psi_pm_Wb) {
  f_iq_.configure(config.firmware.telemetry_filter_s, ts_);
}

std::error_code LoadDriveFirmware::enable(bool on) {
  if (!on) {
    // A disable from the master is obeyed at any time, also during the drive's own ordered
    // stop (as a safe torque off would be): the gates go off and that stop's fault latches.
    if (state_ == drivers::DriveState::stopping) trip(pending_fault_);
    torque_cmd_Nm_ = 0;
    runaway_Nm_ = 0;
    if (state_ != drivers::DriveState::faulted) state_ = drivers::DriveState::disabled;
    return {};
  }
  if (state_ == drivers::DriveState::stopping || state_ == drivers::DriveState::faulted)
    return make_error_code(errc::device_fault);
  state_ = drivers::DriveState::running;
  return {};
}

std::error_code LoadDriveFirmware::set_torque_Nm(double torque_Nm) {
  if (state_ == drivers::DriveState::stopping) return make_error_code(errc::device_fault);
  if (torque_Nm == 0.0 && runaway_Nm_ != 0.0) {
    runaway_Nm_ = 0.0;
    torque_cmd_Nm_ = 0.0;  // the faulty reference is dropped, not ramped out
  }
  if (!std::isfinite(torque_Nm) || torque_Nm < 0 ||
      torque_Nm > kt_ * cfg_.load.current_limit_A)
    return make_error_code(errc::invalid_argument);
  torque_set_Nm_ = torque_Nm;
  return {};
}

std::error_code LoadDriveFirmware::reset_fault() {
  if (state_ == drivers::DriveState::faulted) {
    state_ = drivers::DriveState::disabled;
    fault_ = drivers::Fault::none;
  }
  return {};
}

void LoadDriveFirmware::trip(drivers::Fault fault) {
  if (state_ != drivers::DriveState::faulted) fault_ = fault;
  state_ = drivers::DriveState::faulted;
  torque_cmd_Nm_ = 0;
}

void LoadDriveFirmware::stop_and_latch(drivers::Fault fault) {
  if (state_ != drivers::DriveState::running) {
    if (state_ != drivers::DriveState::stopping) trip(fault);
    return;
  }
  state_ = drivers::DriveState::stopping;
  pending_fault_ = fault;
  torque_set_Nm_ = 0.0;
}

double LoadDriveFirmware::control(double iq_measured_A) {
  if (state_ == drivers::DriveState::stopping && torque_cmd_Nm_ == 0.0) trip(pending_fault_);
  if (state_ == drivers::DriveState::running || state_ == drivers::DriveState::stopping) {
    const double max_step = cfg_.load.torque_ramp_Nm_per_s * ts_;
    torque_cmd_Nm_ += std::clamp(torque_set_Nm_ - torque_cmd_Nm_, -max_step, max_step);
  } else {
    torque_cmd_Nm_ = 0;
  }
  if (runaway_Nm_ != 0 && state_ == drivers::DriveState::running && torque_set_Nm_ > 0)
    torque_cmd_Nm_ = -runaway_Nm_;
  f_iq_.update(iq_measured_A);
  if (window_left_ > 0) {
    w_iq_.add(iq_measured_A);
    b_iq_.add(iq_measured_A);
    if (--window_left_ == 0) {
      window_result_ = {};
      window_result_.samples = static_cast<std::uint32_t>(w_iq_.count());
      window_result_.torque_Nm = kt_ * w_iq_.mean();
      window_result_.batch_torque_Nm = b_iq_.means(kt_);
    }
  }
  return torque_cmd_Nm_ / kt_;
}

void LoadDriveFirmware::begin_window(std::int64_t steps) {
  window_left_ = steps;
  w_iq_.reset();
  b_iq_.reset(steps, cfg_.firmware.window_batches);
}

drivers::LoadTelemetry LoadDriveFirmware::telemetry() const {
  return {kt_ * f_iq_.value(), f_iq_.value(), state_, fault_, std::nullopt};
}

}  // namespace synbench::emulator::firmware
