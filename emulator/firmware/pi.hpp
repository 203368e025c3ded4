// Discrete PI controller with output clamp and conditional-integration anti-windup.
#pragma once

#include <algorithm>

namespace synbench::emulator::firmware {

class Pi {
 public:
  void set_gains(double kp, double ki) { kp_ = kp; ki_ = ki; }
  void set_limits(double lo, double hi) { lo_ = lo; hi_ = hi; }
  void reset(double integral = 0) { integral_ = integral; }
  double integral() const { return integral_; }

  // One update; `hold` freezes the integrator (the output is limited downstream).
  double update(double error, double dt, bool hold = false) {
    const double p = kp_ * error;
    const double candidate = integral_ + ki_ * error * dt;
    const double out = p + candidate;
    const bool saturating = (out > hi_ && error > 0) || (out < lo_ && error < 0);
    if (!hold && !saturating) integral_ = std::clamp(candidate, lo_, hi_);
    return std::clamp(p + integral_, lo_, hi_);
  }

 private:
  double kp_ = 0, ki_ = 0, lo_ = -1e300, hi_ = 1e300, integral_ = 0;
};

// First-order low-pass on a fixed step.
class LowPass {
 public:
  void configure(double tau_s, double dt_s) { a_ = dt_s / (tau_s + dt_s); }
  double update(double x) { return y_ += a_ * (x - y_); }
  double value() const { return y_; }
  void reset(double y) { y_ = y; }

 private:
  double a_ = 1, y_ = 0;
};

}  // namespace synbench::emulator::firmware
