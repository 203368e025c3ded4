// The twin's meter as commercial instruments see it, beside synbench's gated VFC meter: the
// free-running totalizers of the two VFC channels and of a time base (meter "totalizer":
// counters that wrap at their register's range), and a DC power meter that reports each
// side's average power over its own update interval (meter "power"). Both come from the same
// converters as the gate (VfcMeter, with its calibration errors), so every meter kind measures
// the same plant the same way.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "drivers/profile/device_profile.hpp"
#include "emulator/twin.hpp"

namespace synbench::emulator {

class TwinInstruments {
 public:
  // The power meter's update interval: a DC power analyser averages over a few line periods.
  static constexpr double kPowerInterval_s = 0.02;

  // time_base_Hz from the totalizer meter profile among `profiles` (1 MHz without one).
  TwinInstruments(const Twin& twin, const std::vector<drivers::DeviceProfile>& profiles);

  // After each step of the twin (TwinSignals::advance, every millisecond).
  void update(const Twin& twin);
  // The value of total_m, total_g, time_base_ticks, pdcm_W or pdcg_W; empty for other signals.
  std::optional<double> value(const Twin& twin, const drivers::ProfileSignal& s) const;

  // Where the three counters stood at twin time 0 (test hook: a counter about to wrap; a real
  // counter's power-on value is arbitrary too).
  void set_counter_start(std::uint64_t total_m, std::uint64_t total_g, std::uint64_t ticks) {
    start_[0] = total_m;
    start_[1] = total_g;
    start_[2] = ticks;
  }
  double time_base_Hz() const { return time_base_Hz_; }

 private:
  double time_base_Hz_ = 1e6;
  double f0_Hz_, kf_Hz_per_A_;
  std::uint64_t start_[3] = {0, 0, 0};
  // The power meter's running interval and its last published averages.
  double t0_s_ = 0, m0_ = 0, g0_ = 0, udc_sum_Vs_ = 0, t_last_s_ = 0;
  double pdcm_W_ = 0, pdcg_W_ = 0;
};

}  // namespace synbench::emulator
