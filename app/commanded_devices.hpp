// The drives as the bench thread commands them, with the last speed, current angle and load
// torque written to each remembered: what the bench commands now, whoever wrote it (manual
// setpoints, a sweep's point procedure with its load ramp, an ordered stop). The status carries
// it (status.commanded), so the Live view draws the setpoint a sweep runs instead of the manual
// one. Pass-through decorators; only the bench thread calls them.
#pragma once

#include <optional>

#include "drivers/devices.hpp"

namespace synbench::app {

struct Commanded {
  std::optional<double> speed_rpm, angle_deg, load_Nm;  // empty until first written
};

class CommandedDevices {
 public:
  explicit CommandedDevices(drivers::BenchDevices inner);
  // The inner devices with the two drives replaced by the recording ones.
  drivers::BenchDevices devices();
  const Commanded& commanded() const { return commanded_; }

 private:
  static std::error_code note(std::error_code ec, std::optional<double>& slot, double v) {
    if (!ec) slot = v;  // a write the link lost is not what the drive runs with
    return ec;
  }
  class Synrm final : public drivers::SynrmDrive {
   public:
    Synrm(drivers::SynrmDrive* d, Commanded& c) : d_(d), c_(c) {}
    std::error_code enable(bool on) override { return d_->enable(on); }
    std::error_code disable_once() override { return d_->disable_once(); }
    std::error_code set_speed_rpm(double v) override { return note(d_->set_speed_rpm(v), c_.speed_rpm, v); }
    std::error_code set_angle_deg(double v) override { return note(d_->set_angle_deg(v), c_.angle_deg, v); }
    std::error_code set_pwm(drivers::Pwm p) override { return d_->set_pwm(p); }
    std::error_code set_estimator(drivers::Estimator e) override { return d_->set_estimator(e); }
    std::error_code reset_fault() override { return d_->reset_fault(); }
    std::error_code read(drivers::SynrmTelemetry& out) override { return d_->read(out); }
    std::error_code read_window(drivers::SynrmWindow& out) override { return d_->read_window(out); }
    std::string error_detail() const override { return d_->error_detail(); }
    drivers::TelemetryResolution resolution() const override { return d_->resolution(); }
    double stop_time_s() const override { return d_->stop_time_s(); }

   private:
    drivers::SynrmDrive* d_;
    Commanded& c_;
  };
  class Load final : public drivers::LoadDrive {
   public:
    Load(drivers::LoadDrive* d, Commanded& c) : d_(d), c_(c) {}
    std::error_code enable(bool on) override { return d_->enable(on); }
    std::error_code disable_once() override { return d_->disable_once(); }
    std::error_code set_torque_Nm(double v) override { return note(d_->set_torque_Nm(v), c_.load_Nm, v); }
    std::error_code reset_fault() override { return d_->reset_fault(); }
    std::error_code read(drivers::LoadTelemetry& out) override { return d_->read(out); }
    std::error_code read_window(drivers::LoadWindow& out) override { return d_->read_window(out); }
    std::string error_detail() const override { return d_->error_detail(); }
    double stop_time_s() const override { return d_->stop_time_s(); }

   private:
    drivers::LoadDrive* d_;
    Commanded& c_;
  };

  drivers::BenchDevices inner_;
  Commanded commanded_;
  Synrm synrm_;
  Load load_;
};

}  // namespace synbench::app
