// The ordered stop: load torque to zero (the SynRM holding the speed its shaft has), then the
// speed, then both drives disabled. One sequence
// for everyone who stops the bench: the safety supervisor after a trip, the point procedure after
// its window or a fault, the sweep engine between configurations and at the end, the daemon's
// runtime on a user's disable or a shutdown. Each step is
// bounded, so a drive that does not answer cannot keep the bench running. Pure logic on the time
// and the telemetry it is given.
#pragma once

#include <optional>

#include "bench/load_ramp.hpp"
#include "drivers/devices.hpp"

namespace synbench::bench {

struct OrderedStopOptions {
  // The load torque comes off at this rate (a sensorless drive at a high current angle must
  // follow the acceleration); 0: commanded to zero at once, at the load drive's own ramp.
  double load_ramp_Nm_per_s = 0.0;
  double load_gone_Nm = 0.05;
  // Step one may take the ramp plus this; a load that has not let go by then is disabled before
  // the speed comes down, so the SynRM is never dragged by it.
  double load_timeout_s = 1.0;
  double stopped_speed_rpm = 20.0;
  double speed_timeout_s = 10.0;  // step two, then both disabled regardless
  // Disable as soon as the load is gone, without bringing the speed down (a drive that lost the
  // shaft has nothing to decelerate).
  bool coast = false;
};

enum class StopStep { idle, load, speed, done };

class OrderedStop {
 public:
  // Starts from the load torque in force (`from_Nm`, for the ramp).
  void begin(const drivers::BenchDevices& dev, const OrderedStopOptions& opt, double now_s,
             double from_Nm);
  // One tick with the telemetry just read (empty: not read). Returns true on the tick that
  // disabled both drives.
  bool tick(double now_s, const std::optional<drivers::SynrmTelemetry>& synrm,
            const std::optional<drivers::LoadTelemetry>& load);
  // Forgets a stop in progress without commanding anything (another owner took over).
  void cancel() { step_ = StopStep::idle; }

  bool active() const { return step_ == StopStep::load || step_ == StopStep::speed; }
  StopStep step() const { return step_; }
  // Once done: whether a step ran out of time instead of seeing its condition.
  bool timed_out() const { return timed_out_; }
  double began_s() const { return began_s_; }

 private:
  void disable_both();

  drivers::BenchDevices dev_{};
  OrderedStopOptions opt_;
  StopStep step_ = StopStep::idle;
  LoadRamp ramp_{0.0};
  double began_s_ = 0, step_since_s_ = 0, last_tick_s_ = 0, load_deadline_s_ = 0;
  bool timed_out_ = false;
  std::optional<double> hold_speed_rpm_;  // the shaft's speed at the step's first telemetry
};

}  // namespace synbench::bench
