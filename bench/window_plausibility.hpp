// Plausibility of one measurement window's results before they become a point record. A
// register in its limits can still hold a value no window can have (a current magnitude of
// -99 A, a NaN, a window of no samples); such a point is refused with the field named, never
// stored: a wrong efficiency in the database is worse than a missing one. Pure logic.
#pragma once

#include <optional>
#include <string>

#include "drivers/devices.hpp"

namespace synbench::bench {

// The first implausible field as "window_im_A: -99 A is negative (a current magnitude)", or
// nothing. Field names are the register map's (docs/register-map.md).
std::optional<std::string> implausible_window(const drivers::SynrmWindow& w, const drivers::LoadWindow& load,
                                              const drivers::MeterReading& meter);

}  // namespace synbench::bench
