// The probe: every readable signal of a device read once, each in a request of its own (so one
// refused address does not hide the others), through the same SignalIo decoding the bench uses,
// with the raw words kept beside the decoded value. What `synbench bench check --probe` prints:
// the first thing anyone does with a new drive. Reads only; it never writes.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "drivers/bus/register_bus.hpp"
#include "drivers/profile/device_profile.hpp"

namespace synbench::drivers {

struct ProbeRow {
  DeviceKind device = DeviceKind::synrm_drive;
  std::string profile;  // the profile's name
  std::string signal;
  RegisterKind table = RegisterKind::holding;
  std::uint16_t address = 0;
  std::uint16_t count = 1;  // addresses the signal occupies
  std::uint8_t unit_id = 1;
  std::vector<std::uint16_t> raw;  // the words as read (coils, discrete inputs: 0 or 1); empty when the read failed
  std::optional<double> value;     // engineering value; for an enumerated signal the bench's code
  std::string label;               // an enumerated signal's label ("disabled", "overcurrent", ...)
  std::string unit;
  std::string error;               // why there is no value (the link's error, or why the raw words do not decode)
};

// One row per readable signal, in the profile's order (table, unit id, address).
std::vector<ProbeRow> probe_device(RegisterBus& bus, const DeviceProfile& profile);

}  // namespace synbench::drivers
