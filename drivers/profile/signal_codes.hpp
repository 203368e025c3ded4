// Enumerated signals (state, fault_code, estimator, ...) between the bench's codes and a
// device's own numbers: the profile's `values` map the catalogue's labels to the device's
// numbers; without them the device uses the bench's codes. Shared by the drivers (reading a
// device) and the emulator (serving one), so both sides agree by construction.
#pragma once

#include <system_error>

#include "drivers/profile/device_profile.hpp"

namespace synbench::drivers {

// Whether the catalogue gives the signal labels (an enumerated signal).
bool is_enumerated(DeviceKind kind, const ProfileSignal& s);

// Whether the signal carries a fault code (fault_code, window_fault_code): those never fail to
// decode; a code without a label is Fault::unknown.
bool is_fault_code(const ProfileSignal& s);

// Device number -> bench code. A number not among the device's reads as the signal's
// `otherwise` label, or for a fault code as Fault::unknown; else errc::protocol (a value the
// bench cannot interpret is never data). Non-enumerated signals pass unchanged.
std::error_code to_bench_code(DeviceKind kind, const ProfileSignal& s, double device_value, double& code);

// Bench code -> device number (a label's first listed number). errc::not_supported when the
// device has no number for the label,
// errc::invalid_argument when the code is not one of the catalogue's.
std::error_code to_device_value(DeviceKind kind, const ProfileSignal& s, double code, double& device_value);

}  // namespace synbench::drivers
