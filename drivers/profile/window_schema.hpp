// Which measurement window a profile's device has, and which meter: the window signals of a
// drive are a group mapped all or none (none: the bench keeps the window, sampling telemetry
// every poll_period_ms), and a vfc_meter is a gate, a totalizer or a power meter, each with its
// own required signals. Part of parse_device_profile; docs/device-profile.md is the schema.
#pragma once

#include "drivers/json.hpp"


#include <optional>
#include <string_view>
#include <vector>

#include "drivers/profile/device_profile.hpp"

namespace synbench::drivers {

std::string_view name(MeterKind k);
std::optional<MeterKind> parse_meter_kind(std::string_view s);

// Reads the top-level window and meter keys of `doc` into `profile` (kind already set) and
// checks that the signals `doc` maps form the groups they require. Errors carry JSON pointers.
void parse_window_schema(const synbench::Json& doc, DeviceProfile& profile, std::vector<ProfileError>& errors);

// Whether the bench keeps this device's window from polled telemetry (a drive without window
// signals, a power meter) rather than the device.
bool host_window(const DeviceProfile& profile);

}  // namespace synbench::drivers
