// Human-readable views of the profile data: the register map of a set of profiles, and the
// signal catalogue. docs/register-map.md and a section of docs/device-profile.md are their
// output, and tests/drivers fails when those files no longer match it.
#pragma once

#include <span>
#include <string>

#include "drivers/profile/device_profile.hpp"

namespace synbench::drivers {

// A complete Markdown document: a preamble, then one table per profile, rows ordered by table,
// unit id and address.
std::string render_register_map(std::span<const DeviceProfile> profiles);

// One table per device kind: signal, role, required, unit, meaning.
std::string render_signal_catalogue();

}  // namespace synbench::drivers
