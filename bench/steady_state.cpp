// Band and least-squares slope checks over a sliding span.
#include "bench/steady_state.hpp"

#include <algorithm>
#include <cmath>

namespace synbench::bench {

void SteadyStateGate::add(double t_s, double speed_rpm, double im_A, double power_W) {
  Sample s{t_s, {speed_rpm, im_A, power_W}};
  if (b_.average_s > 0) {
    raw_.push_back(s);
    for (int k = 0; k < 3; ++k) sum_[k] += s.v[k];
    while (raw_.size() > 1 && raw_.front().t < t_s - b_.average_s) {
      for (int k = 0; k < 3; ++k) sum_[k] -= raw_.front().v[k];
      raw_.pop_front();
    }
    // A mean over less than its time is not one yet.
    if (t_s - raw_.front().t < 0.9 * b_.average_s) return;
    const double n = static_cast<double>(raw_.size());
    for (int k = 0; k < 3; ++k) s.v[k] = sum_[k] / n;
  }
  samples_.push_back(s);
  while (samples_.size() > 2 && samples_.front().t < t_s - b_.span_s) samples_.pop_front();
}

bool SteadyStateGate::signal_steady(int k, double band) const {
  double lo = samples_.front().v[k], hi = lo;
  double st = 0, sv = 0, stt = 0, stv = 0;
  const double t0 = samples_.front().t;
  for (const auto& s : samples_) {
    lo = std::min(lo, s.v[k]);
    hi = std::max(hi, s.v[k]);
    const double t = s.t - t0;
    st += t;
    sv += s.v[k];
    stt += t * t;
    stv += t * s.v[k];
  }
  if (hi - lo > band) return false;
  const double n = static_cast<double>(samples_.size());
  const double den = n * stt - st * st;
  const double slope = den > 0 ? (n * stv - st * sv) / den : 0.0;
  return std::fabs(slope) * b_.span_s <= band;
}

bool SteadyStateGate::steady() const {
  if (samples_.size() < 3 || samples_.back().t - samples_.front().t < 0.9 * b_.span_s) return false;
  double im = 0, p = 0;
  for (const auto& s : samples_) {
    im += s.v[1];
    p += s.v[2];
  }
  const double n = static_cast<double>(samples_.size());
  const double im_band = std::max(b_.im_band_min_A, b_.im_band_rel * std::fabs(im / n));
  const double p_band = std::max(b_.power_band_min_W, b_.power_band_rel * std::fabs(p / n));
  return signal_steady(0, b_.speed_band_rpm) && signal_steady(1, im_band) && signal_steady(2, p_band);
}

}  // namespace synbench::bench
