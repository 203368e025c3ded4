// Steady-state gate: a point is settled when, over the last `span_s` of samples, each watched
// signal stays inside its band and its fitted slope moves it less than the band over the span.
// With `average_s` > 0 the checks see each signal's trailing mean over that time instead of the
// samples: a configuration that injects (HFI's carrier, the PRBS of EEMF-RLS) makes the speed,
// I_m and P_dcM fluctuate by design, around a mean that settles like any other.
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
  double average_s = 0.0;        // trailing mean the checks see; 0: the samples themselves
  bool operator==(const SteadyStateBands&) const = default;
};

class SteadyStateGate {
 public:
  explicit SteadyStateGate(SteadyStateBands bands) : b_(bands) {}
  void reset() {
    samples_.clear();
    raw_.clear();
    sum_[0] = sum_[1] = sum_[2] = 0;
  }
  void add(double t_s, double speed_rpm, double im_A, double power_W);
  bool steady() const;

 private:
  struct Sample {
    double t, v[3];
  };
  bool signal_steady(int k, double band) const;
  SteadyStateBands b_;
  std::deque<Sample> samples_;  // what the checks see (trailing means with average_s)
  std::deque<Sample> raw_;      // the samples of the last average_s
  double sum_[3] = {0, 0, 0};
};

}  // namespace synbench::bench
