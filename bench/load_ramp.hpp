// The bench's load-torque setpoint ramp: the bench moves the PMSM's torque setpoint itself at a
// gentle rate (PointOptions::load_ramp_Nm_per_s) instead of stepping it and leaving the ramp to
// the load drive (10 N m/s): a sensorless observer must follow the deceleration a load change
// causes until the 3 Hz speed loop answers (docs/record.md). Intermediate setpoints lie on a
// 1/1024 N m grid, exact in a 32-bit float register, so a ramp commands the same torques over
// Modbus as in-process. Pure logic on the time step it is given.
#pragma once

namespace synbench::bench {

// The bench's rate (PointOptions, a user's disable).
inline constexpr double kBenchLoadRamp_Nm_per_s = 2.0;

class LoadRamp {
 public:
  explicit LoadRamp(double rate_Nm_per_s) : rate_(rate_Nm_per_s) {}
  // The setpoint in force now and where to go; a rate <= 0 jumps at the next step.
  void start(double from_Nm, double to_Nm) {
    cmd_ = from_Nm;
    target_ = to_Nm;
  }
  // A new target from the setpoint in force.
  void retarget(double to_Nm) { target_ = to_Nm; }
  // Advances by dt and returns the setpoint to command.
  double step(double dt_s);
  bool done() const { return cmd_ == target_; }
  double command() const { return cmd_; }

 private:
  double rate_;
  double cmd_ = 0, target_ = 0;
};

}  // namespace synbench::bench
