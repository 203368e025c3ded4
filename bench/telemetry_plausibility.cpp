// Frozen values, current into a shaft at rest, impossible signs and ranges.
#include "bench/telemetry_plausibility.hpp"

#include <cmath>
#include <cstring>
#include "drivers/printf_text.hpp"

namespace synbench::bench {
namespace {

std::uint64_t bits_of(double v) {
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

}  // namespace

TelemetryPlausibility::TelemetryPlausibility(PlausibilityLimits limits) : lim_(limits) {
  set_resolution({});
}

void TelemetryPlausibility::set_resolution(const drivers::TelemetryResolution& r) {
  resolution_ = r;
  for (std::size_t i = 0; i < kWatched; ++i) {
    const auto& w = drivers::kFrozenWatched[i];
    watchable_[i] = drivers::frozen_watchable(r.*w.step, lim_.noise_floor.*w.noise);
  }
  frozen_ = {};
}

std::vector<drivers::FrozenBlindSpot> TelemetryPlausibility::blind_spots() const {
  return drivers::frozen_blind_spots(resolution_, lim_.noise_floor);
}

void TelemetryPlausibility::reset() {
  frozen_ = {};
  at_rest_since_s_ = -1;
}

std::optional<Implausibility> TelemetryPlausibility::frozen(double now_s, std::size_t i, double value,
                                                            bool watched) {
  Frozen& f = frozen_[i];
  const auto& w = drivers::kFrozenWatched[i];
  // Exactly 0 is a value a drive really holds (no encoder edges at standstill), not a sign of a
  // hung task; and only a running drive must show its noise.
  if (!watched || !watchable_[i] || value == 0.0 || !std::isfinite(value)) {
    f.valid = false;
    return std::nullopt;
  }
  const std::uint64_t b = bits_of(value);
  if (!f.valid || f.bits != b) {
    f = Frozen{b, 1, now_s, true};
    return std::nullopt;
  }
  ++f.reads;
  const double span_s = now_s - f.since_s;
  if (f.reads < lim_.frozen_reads || span_s < lim_.frozen_s) return std::nullopt;
  char buf[160];
  std::snprintf(buf, sizeof buf, "frozen at %.6g %s, bit for bit, for %d reads (%.2f s) while the drive runs",
                value, w.unit, f.reads, span_s);
  return Implausibility{w.name, buf};
}

std::optional<Implausibility> TelemetryPlausibility::check(double now_s, const drivers::SynrmTelemetry& t) {
  // Signs and ranges hold whatever the state: a sensor does not read a negative magnitude
  // because the gates are off.
  if (std::isnan(t.im_A) || t.im_A < lim_.min_im_A)
    return Implausibility{"im_A", drivers::printf_text("%.3g A is negative: a current magnitude is never below %.3g A", t.im_A,
                                         lim_.min_im_A)};
  if (std::isnan(t.udc_V) || t.udc_V < lim_.min_udc_V)
    return Implausibility{"udc_V", drivers::printf_text("%.4g V is below %.3g V: the DC bus never reverses", t.udc_V,
                                          lim_.min_udc_V)};
  // No sensor mapped is no reading, not a broken one.
  if (t.temp_C && (std::isnan(*t.temp_C) || *t.temp_C < lim_.min_temp_C || *t.temp_C > lim_.max_temp_C))
    return Implausibility{"temp_C", drivers::printf_text("%.4g degC is outside [%.4g, %.4g] degC: a broken winding sensor",
                                           *t.temp_C, lim_.min_temp_C, lim_.max_temp_C)};
  if (std::isnan(t.speed_rpm))
    return Implausibility{"speed_rpm", "is not a number"};

  const bool run = drivers::running(t.state);
  // On the voltage limit the controller clamps its references: leave them out then.
  std::optional<Implausibility> found;
  for (std::size_t i = 0; i < kWatched; ++i) {
    const auto& w = drivers::kFrozenWatched[i];
    const bool voltage = w.value == &drivers::SynrmTelemetry::ud_V || w.value == &drivers::SynrmTelemetry::uq_V;
    auto f = frozen(now_s, i, t.*w.value, run && !(voltage && t.voltage_limited));
    if (f && !found) found = std::move(f);
  }
  if (found) return found;

  const bool at_rest = run && std::fabs(t.speed_rpm) < lim_.rest_speed_rpm && t.im_A > lim_.rest_current_A;
  if (!at_rest) {
    at_rest_since_s_ = -1;
    return std::nullopt;
  }
  if (at_rest_since_s_ < 0) at_rest_since_s_ = now_s;
  if (now_s - at_rest_since_s_ >= lim_.rest_s)
    return Implausibility{"speed_rpm",
                          drivers::printf_text("%.3g rpm, the shaft at rest, with %.3g A flowing for %.2f s: a dead speed sensor or a "
                                 "locked rotor",
                                 t.speed_rpm, t.im_A, now_s - at_rest_since_s_)};
  return std::nullopt;
}

}  // namespace synbench::bench
