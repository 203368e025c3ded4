// Which of the SynRM drive's telemetry values the frozen-telemetry check can watch: a value is
// taken for frozen when it reads bit for bit the same for a second while the drive runs, which
// proves a hung firmware task only when the register's step is finer than the noise a running
// drive shows on that value. A current in i16 at 0.01 A is coarser than the few mA a filtered
// telemetry current wanders: steady, it reads the same step after step, and a frozen value
// cannot be told from a steady one. Shared by the supervisor (bench/telemetry_plausibility.hpp)
// and `synbench bench check`, which reports what cannot be watched.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "drivers/devices.hpp"
#include "drivers/profile/device_profile.hpp"

namespace synbench::drivers {

// The least standard deviation a running drive's telemetry shows on each watched value over a
// few seconds at steady state, with a margin of 3 below it, so that a step just finer than the
// floor still changes between reads (a step of a third of sigma leaves a run of 20 equal reads
// no chance). Measured on the twin (tests/emulator/telemetry_noise_test.cpp, read every 50 ms
// for 5 s at 300 rpm unloaded, 1000 rpm 2 N m, 1500 rpm 3.5 N m; the quietest point quoted):
// speed_rpm 0.081 rpm, im_A 0.56 mA, id_A 0.30 mA, iq_A 0.43 mA, ud_V 0.016 V, uq_V 0.015 V
// (uq_V at 1500 rpm 3.5 N m, on the voltage limit, where the speed loop no longer integrates:
// 0.019 V before it stopped winding up, issue 37).
// The currents agree with physics.md: sigma_i = 15.8 mA per 100 us ADC sample through the
// firmware's 50 ms telemetry filter is 15.8 mA x sqrt(1e-4 / (2 x 0.05)) = 0.5 mA. So 1 mA
// steps are not watched (as i16 at 0.001 A, a steady current froze 1 run in 25), 0.01 A
// steps certainly not (6 in 6), uA steps are. A drive that filters its telemetry harder than
// the twin is quieter: its coarse registers may still hold still, and the floors would have to
// come from its own measurement.
struct TelemetryNoise {
  double speed_rpm, im_A, id_A, iq_A, ud_V, uq_V;
};
inline constexpr TelemetryNoise kRunningNoise{
    .speed_rpm = 0.015, .im_A = 1.5e-4, .id_A = 1e-4, .iq_A = 1.4e-4, .ud_V = 0.004, .uq_V = 0.005};

// One watched value: its name and unit, where its step, floor and value live.
struct WatchedSignal {
  const char* name;
  const char* unit;
  double TelemetryResolution::*step;
  double TelemetryNoise::*noise;
  double SynrmTelemetry::*value;
};
inline constexpr std::array<WatchedSignal, 6> kFrozenWatched{{
    {"speed_rpm", "rpm", &TelemetryResolution::speed_rpm, &TelemetryNoise::speed_rpm, &SynrmTelemetry::speed_rpm},
    {"im_A", "A", &TelemetryResolution::im_A, &TelemetryNoise::im_A, &SynrmTelemetry::im_A},
    {"id_A", "A", &TelemetryResolution::id_A, &TelemetryNoise::id_A, &SynrmTelemetry::id_A},
    {"iq_A", "A", &TelemetryResolution::iq_A, &TelemetryNoise::iq_A, &SynrmTelemetry::iq_A},
    {"ud_V", "V", &TelemetryResolution::ud_V, &TelemetryNoise::ud_V, &SynrmTelemetry::ud_V},
    {"uq_V", "V", &TelemetryResolution::uq_V, &TelemetryNoise::uq_V, &SynrmTelemetry::uq_V},
}};

// A step finer than the noise: a frozen value shows as one.
constexpr bool frozen_watchable(double step, double noise) { return step < noise; }

// A value the check leaves alone, and why.
struct FrozenBlindSpot {
  std::string signal;
  std::string unit;
  double step = 0;   // the register's step
  double noise = 0;  // the running drive's noise floor
  // "id_A: 0.01 A steps, coarser than its noise (~3 mA): a frozen value cannot be told from a
  // steady one"
  std::string describe() const;
};

// The watched values whose steps are too coarse, in kFrozenWatched's order.
std::vector<FrozenBlindSpot> frozen_blind_spots(const TelemetryResolution& r,
                                                const TelemetryNoise& noise = kRunningNoise);

// The step of one signal's decoded value: |scale| for an integer type (a masked field is read
// shifted down to its lowest bit, so its step is |scale| too), 0 for f32 (continuous).
double signal_step(const ProfileSignal& s);
// The steps of a SynRM drive profile's watched signals (0 for one it does not map: absent
// values are left out of the check anyway).
TelemetryResolution telemetry_resolution(const DeviceProfile& synrm);

}  // namespace synbench::drivers
