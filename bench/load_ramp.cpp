// Load-torque setpoint ramp on the 1/1024 N m grid.
#include "bench/load_ramp.hpp"

#include <algorithm>
#include <cmath>

namespace synbench::bench {

double LoadRamp::step(double dt_s) {
  if (rate_ <= 0) return cmd_ = target_;
  const double max_step = rate_ * dt_s;
  const double next = cmd_ + std::clamp(target_ - cmd_, -max_step, max_step);
  // A ramp slower than one grid step per tick moves unrounded rather than not at all.
  const double on_grid = std::round(next * 1024.0) / 1024.0;
  cmd_ = (next == target_ || on_grid == cmd_) ? next : on_grid;
  return cmd_;
}

}  // namespace synbench::bench
