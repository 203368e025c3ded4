// Wall-clock time for the bench on hardware or on `synbench emulate`: waiting sleeps. With a
// time scale X, X bench seconds pass per wall second, to match an emulator run with
// --time-scale X (1 on hardware).
#pragma once

#include <chrono>
#include <thread>

#include "drivers/clock.hpp"

namespace synbench::drivers {

class RealTimeClock final : public Clock {
 public:
  explicit RealTimeClock(double time_scale = 1.0)
      : scale_(time_scale), start_(std::chrono::steady_clock::now()) {}

  double now_s() const override {
    return scale_ * std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  void wait_until(double t_s) override {
    const auto wake = start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                   std::chrono::duration<double>(t_s / scale_));
    std::this_thread::sleep_until(wake);
  }
  double time_scale() const { return scale_; }

 private:
  double scale_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace synbench::drivers
