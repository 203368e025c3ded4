// Plausibility of one measurement window's results before they become a point record. A
// register in its limits can still hold a value no window can have (a current magnitude of
// -99 A, a NaN, a window of no samples, an efficiency above 1, a host window whose clock and the
// meter's disagree); such a point is refused with the field named, never
// stored: a wrong efficiency in the database is worse than a missing one. Pure logic.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "bench/point_record.hpp"
#include "drivers/devices.hpp"

namespace synbench::bench {

// The shortest window a plan or a point may ask for: 10 VFC sub-gates of 10 ms (100 PWM periods
// each at 10 kHz, 1000 counts at the converters' 100 kHz/A span per 1 A), 100 speed-loop periods.
// Shorter, one count or one period is a sizeable part of the mean (docs/sweep-plan.md).
constexpr double kMinWindow_s = 0.1;
// The fewest samples a window may hold and still be stored: the drive's control periods (a
// drive accumulating at 1 kHz holds 100 in kMinWindow_s), or the bench's polls of a host-kept one.
constexpr std::uint32_t min_window_samples(drivers::WindowKeeper k) { return k == drivers::WindowKeeper::host ? 5 : 100; }

// The first implausible field as "window_im_A: -99 A is negative (a current magnitude)", or
// nothing. Field names are the register map's (docs/register-map.md).
std::optional<std::string> implausible_window(const drivers::SynrmWindow& w, const drivers::LoadWindow& load,
                                              const drivers::MeterReading& meter);

// The timing of a window the bench kept (any source of keeper host) against the length asked
// for and the meter's own time base. A host window lasts from its first sample to its last by
// the host's clock; a totalizer's or gate meter's window by the meter's. When the bench stops
// polling (a frozen or starved master) past the window's end, the host window closes late with
// the samples from before, while the meter counts on: the powers then come from different
// spans. Beyond one poll period plus `jitter_s` either way, the first mismatch naming both
// durations ("window: 28.6 s by the SynRM drive's host samples but 20 s asked"), or nothing.
std::optional<std::string> window_timing_mismatch(const drivers::SynrmWindow& w, const drivers::LoadWindow& load,
                                                  const drivers::MeterReading& meter, double requested_s,
                                                  double jitter_s);

// Powers no motor can have, in a finished record: while motoring (pm_W > 0) the input pdcm_W
// must exceed the output pm_W (an efficiency of at most 1), and mechanical output with no
// electrical input is none. Names the fields and values, or nothing.
std::optional<std::string> implausible_powers(const PointRecord& r);

}  // namespace synbench::bench
