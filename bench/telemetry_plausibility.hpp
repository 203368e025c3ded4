// Plausibility of the SynRM drive's live telemetry: values a working drive and its sensors
// cannot report. A decoded register can be in its limits and still be wrong: a firmware task
// that hung leaves a value frozen bit for bit, a dead encoder reads a shaft at rest while
// current flows, a broken sensor or a sign error gives a negative magnitude. The safety
// supervisor feeds every telemetry read here and trips `implausible_telemetry` on the first
// finding. Pure logic on the time it is given; tested with vectors.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "drivers/devices.hpp"
#include "drivers/frozen_watch.hpp"

namespace synbench::bench {

// Thresholds and why (docs/record.md, "What the supervisor checks").
struct PlausibilityLimits {
  // Frozen: an analogue value of a running drive carries ADC noise and PWM ripple in its last
  // bits, so the same bits read after read (of a register fine enough to show that noise) mean
  // the value is no longer being updated. Both
  // a count of consecutive identical reads and a span of bench time must be exceeded, so a bench
  // that polls faster than the drive refreshes (or a twin that lags its clock for a moment) is
  // not taken for a stuck sensor. 1 s: the firmware refreshes telemetry every control period
  // (100 us); nothing physical holds an f32 current or speed for a second.
  int frozen_reads = 20;
  double frozen_s = 1.0;
  // A value is watched only when its register's step (the drive's TelemetryResolution) is finer
  // than the noise a running drive shows on it (drivers/frozen_watch.hpp): an i16 current in
  // 0.01 A steps holds still for seconds at a steady point without anything being stuck.
  drivers::TelemetryNoise noise_floor = drivers::kRunningNoise;
  // Values exactly 0 are left out of the frozen check: a drive at standstill reports a speed of
  // exactly 0 (no encoder edges), a drive on its voltage limit clamps nothing to 0.
  // Current with the shaft at rest: more than `rest_current_A` for `rest_s` with the speed
  // below `rest_speed_rpm` while the drive runs. Break-away from rest takes tens of ms at the
  // bench's loads, and the ordered stop disables the drive below 20 rpm; 2 s of 1 A into a
  // shaft that does not turn is a dead speed sensor or a locked rotor (the 0.55 kW SynRM's
  // magnetising current alone is about 1 A peak at rated flux, so less proves nothing).
  double rest_speed_rpm = 2.0;
  double rest_current_A = 1.0;
  double rest_s = 2.0;
  // Signs and ranges: a current magnitude below zero (beyond a register's rounding), a DC bus
  // below zero (the bus is a capacitor behind a rectifier; a sensor's offset at 0 V is a few
  // volts at most), a winding below -30 degC (a lab bench; an open NTC thermistor reads about
  // -50) or above 250 degC (beyond any insulation class: a shorted sensor; the overtemperature
  // limit trips long before a real winding gets there).
  double min_im_A = -0.01;
  double min_udc_V = -5.0;
  double min_temp_C = -30.0;
  double max_temp_C = 250.0;
};

struct Implausibility {
  std::string signal;  // the telemetry field, e.g. "im_A"
  std::string reason;  // "frozen at 1.2345 A for 25 reads (1.02 s) while the drive runs"
  std::string describe() const { return signal + " " + reason; }
};

class TelemetryPlausibility {
 public:
  explicit TelemetryPlausibility(PlausibilityLimits limits = {});

  // One telemetry read at `now_s`: the first implausibility found, if any.
  std::optional<Implausibility> check(double now_s, const drivers::SynrmTelemetry& t);
  // Forgets the history (after a reset of the bench).
  void reset();
  // The steps of the drive's registers (SynrmDrive::resolution()); values whose steps are not
  // finer than their noise floor are no longer watched for freezing. Default: continuous.
  void set_resolution(const drivers::TelemetryResolution& r);
  // What the frozen check leaves alone with the resolution set.
  std::vector<drivers::FrozenBlindSpot> blind_spots() const;

  const PlausibilityLimits& limits() const { return lim_; }

 private:
  // The signals watched for freezing.
  static constexpr std::size_t kWatched = drivers::kFrozenWatched.size();
  struct Frozen {
    std::uint64_t bits = 0;
    int reads = 0;        // consecutive reads with these bits
    double since_s = 0;   // first of them
    bool valid = false;
  };
  std::optional<Implausibility> frozen(double now_s, std::size_t i, double value, bool watched);

  PlausibilityLimits lim_;
  drivers::TelemetryResolution resolution_;
  std::array<bool, kWatched> watchable_{};
  std::array<Frozen, kWatched> frozen_{};
  double at_rest_since_s_ = -1;
};

}  // namespace synbench::bench
