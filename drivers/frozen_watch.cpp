// Register steps against a running drive's noise.
#include "drivers/frozen_watch.hpp"

#include <cmath>
#include <cstdio>

#include "drivers/profile/number_format.hpp"

namespace synbench::drivers {

std::string FrozenBlindSpot::describe() const {
  // The noise in the unit's thousandths where it is small: "~3 mA" reads better than "~0.003 A".
  const bool milli = noise < 1.0;
  char noise_text[48];
  std::snprintf(noise_text, sizeof noise_text, "~%.2g %s%s", milli ? noise * 1000.0 : noise, milli ? "m" : "",
                unit.c_str());
  return signal + ": " + format_number(step) + " " + unit + " steps, coarser than its noise (" + std::string(noise_text) +
         "): a frozen value cannot be told from a steady one";
}

std::vector<FrozenBlindSpot> frozen_blind_spots(const TelemetryResolution& r, const TelemetryNoise& noise) {
  std::vector<FrozenBlindSpot> out;
  for (const WatchedSignal& w : kFrozenWatched)
    if (!frozen_watchable(r.*w.step, noise.*w.noise)) out.push_back({w.name, w.unit, r.*w.step, noise.*w.noise});
  return out;
}

double signal_step(const ProfileSignal& s) {
  switch (s.encoding.type) {
    case ValueType::u16:
    case ValueType::i16:
    case ValueType::u32:
    case ValueType::i32: return std::fabs(s.encoding.scale);
    case ValueType::boolean:
    case ValueType::f32: return 0.0;
  }
  return 0.0;
}

TelemetryResolution telemetry_resolution(const DeviceProfile& synrm) {
  TelemetryResolution r;
  for (const WatchedSignal& w : kFrozenWatched)
    if (const ProfileSignal* s = synrm.find(w.name)) r.*w.step = signal_step(*s);
  return r;
}

}  // namespace synbench::drivers
