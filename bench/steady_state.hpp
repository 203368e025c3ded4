// Steady-state gate: a point is settled when, over the last `span_s` of samples, each watched
// signal stays inside its band and its fitted slope moves it less than the band over the span.
// Pure logic: samples come with their time, nothing sleeps.
#pragma once

#include <cstddef>
#include <deque>

namespace synbench::bench {

struct SteadyStateBands {
  double span_s = 0.5;
  double speed_band_rpm = 2.0;
  double im_band_rel = 0.01;     // of the mean current
  double im_band_min_A = 0.01;
  double power_band_rel = 0.01;  // of the mean power
  double power_band_min_W = 2.0;
};

class SteadyStateGate {
 public:
  explicit SteadyStateGate(SteadyStateBands bands) : b_(bands) {}
  void reset() { samples_.clear(); }
  void add(double t_s, double speed_rpm, double im_A, double power_W);
  bool steady() const;

 private:
  struct Sample {
    double t, v[3];
  };
  bool signal_steady(int k, double band) const;
  SteadyStateBands b_;
  std::deque<Sample> samples_;
};

}  // namespace synbench::bench
