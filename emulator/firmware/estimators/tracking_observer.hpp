// Phase-locked tracking observer: a PI on an angle error yields speed, its integral the angle.
// Critically damped at the given bandwidth. Used by the encoder speed observer, HFI and EEMF.
#pragma once

#include <cmath>

namespace synbench::emulator::firmware {

class TrackingObserver {
 public:
  void configure(double bandwidth_Hz) {
    set_natural_frequency(2.0 * 3.14159265358979323846 * bandwidth_Hz);
  }
  // Critically damped at wn; an observer may retune it while running (HFI, shaft_stiffness.hpp).
  void set_natural_frequency(double wn_rad_s) {
    kp_ = 2.0 * wn_rad_s;
    ki_ = wn_rad_s * wn_rad_s;
  }
  void reset(double theta_rad, double omega_rad_s) {
    theta_ = theta_rad;
    omega_ = speed_ = omega_rad_s;
  }
  // Advances the angle to the next sample instant with the speed estimate.
  void predict(double dt_s) { theta_ += omega_ * dt_s; }
  // Corrects with the angle error (true minus estimate) measured at this instant.
  void correct(double error_rad, double dt_s) {
    omega_ += ki_ * error_rad * dt_s;
    theta_ += kp_ * error_rad * dt_s;
    speed_ = omega_ + kp_ * error_rad;
  }
  double theta() const { return theta_; }
  double omega() const { return omega_; }
  // The PI's output, integral plus proportional part: the speed the angle moves at (thesis
  // 2.13). The integral alone lags by a second-order low-pass, too slow for a speed loop.
  double speed() const { return speed_; }

 private:
  double kp_ = 0, ki_ = 0, theta_ = 0, omega_ = 0, speed_ = 0;
};

// Second-order band-pass (RBJ biquad, 0 dB at the centre).
class BandPass {
 public:
  void configure(double centre_Hz, double bandwidth_Hz, double fs_Hz) {
    const double w0 = 2.0 * 3.14159265358979323846 * centre_Hz / fs_Hz;
    const double alpha = std::sin(w0) * bandwidth_Hz / (2.0 * centre_Hz);
    const double a0 = 1.0 + alpha;
    b0_ = alpha / a0;
    a1_ = -2.0 * std::cos(w0) / a0;
    a2_ = (1.0 - alpha) / a0;
  }
  double update(double x) {
    const double y = b0_ * x - b0_ * x2_ - a1_ * y1_ - a2_ * y2_;
    x2_ = x1_;
    x1_ = x;
    y2_ = y1_;
    y1_ = y;
    return y;
  }
  double value() const { return y1_; }

 private:
  double b0_ = 0, a1_ = 0, a2_ = 0, x1_ = 0, x2_ = 0, y1_ = 0, y2_ = 0;
};

}  // namespace synbench::emulator::firmware
