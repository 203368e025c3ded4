// The bench's notion of time. Logic takes `now_s` as an argument and never sleeps; only the
// runner waits, through this interface: real time on hardware, virtual time on the twin (where
// waiting advances the simulation, as ArduPilot SITL's simulator is the time master).
#pragma once

namespace synbench::drivers {

class Clock {
 public:
  virtual ~Clock() = default;
  virtual double now_s() const = 0;
  // Returns when now_s() >= t_s.
  virtual void wait_until(double t_s) = 0;
};

}  // namespace synbench::drivers
