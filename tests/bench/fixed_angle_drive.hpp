// A SynRM drive that runs at one current angle whatever it is sent: the twin's drive behind a
// profile that maps the angle setpoint to the wrong register, or firmware that ignores the
// write. What the record's measured angle exists to catch.
#pragma once

#include <string>

#include "drivers/devices.hpp"

namespace synbench::bench::testing {

class FixedAngleDrive : public drivers::SynrmDrive {
 public:
  FixedAngleDrive(drivers::SynrmDrive& inner, double angle_deg) : inner_(inner), angle_deg_(angle_deg) {}
  std::error_code enable(bool on) override { return inner_.enable(on); }
  std::error_code set_speed_rpm(double v) override { return inner_.set_speed_rpm(v); }
  std::error_code set_angle_deg(double) override { return inner_.set_angle_deg(angle_deg_); }
  std::error_code set_pwm(drivers::Pwm v) override { return inner_.set_pwm(v); }
  std::error_code set_estimator(drivers::Estimator v) override { return inner_.set_estimator(v); }
  std::error_code reset_fault() override { return inner_.reset_fault(); }
  std::error_code read(drivers::SynrmTelemetry& out) override { return inner_.read(out); }
  std::error_code read_window(drivers::SynrmWindow& out) override { return inner_.read_window(out); }
  std::string error_detail() const override { return inner_.error_detail(); }

 private:
  drivers::SynrmDrive& inner_;
  double angle_deg_;
};

}  // namespace synbench::bench::testing
