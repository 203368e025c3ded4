// The logical signals the bench knows per device kind: name, role, whether a profile must map
// it, and its engineering unit. A profile maps these names to registers; the names are the
// contract with the rest of synbench, so a profile may neither rename nor add signals.
#pragma once

#include <array>
#include <optional>
#include <span>
#include <string_view>

namespace synbench::drivers {

enum class DeviceKind { synrm_drive, load_drive, vfc_meter };

// What the bench does with a signal. Roles the bench writes need write access in the profile;
// the others need read access.
enum class SignalRole {
  command,          // setpoint or mode the bench writes
  heartbeat,        // counter the bench increments; the device trips when it stalls
  fault_reset,      // writing 1 clears a latched fault
  window_start,     // writing 1 opens a measurement window (gate)
  window_length,    // length of the next window
  window_status,    // 0 idle, 1 open, 2 done
  window_sequence,  // increments (mod 2^16) each time a window closes
  window_result,    // a value accumulated over the last closed window
  telemetry,        // a live (filtered) value
  calibration,      // a device constant the bench may read back or set
};

struct SignalSpec {
  std::string_view name;
  SignalRole role;
  bool required;
  std::string_view unit;  // engineering unit after scaling; empty when dimensionless
  std::string_view doc;   // meaning
  // An enumerated signal's labels, indexed by the bench's code (state: labels[3] == "faulted").
  // A profile's "values" map these labels to the device's own numbers.
  std::span<const std::string_view> labels = {};
  // An array of "count" consecutive values (2..64, the profile says how many): a window's batch
  // means. A profile must give an array signal a count and may not give one to any other.
  bool array = false;
};

inline constexpr int kMinArrayCount = 2, kMaxArrayCount = 64;

inline constexpr std::array<DeviceKind, 3> kDeviceKinds{DeviceKind::synrm_drive, DeviceKind::load_drive,
                                                         DeviceKind::vfc_meter};

std::string_view name(DeviceKind k);
std::string_view name(SignalRole r);
std::optional<DeviceKind> parse_device_kind(std::string_view s);

// Whether the bench writes signals of this role (else it only reads them).
constexpr bool bench_writes(SignalRole r) {
  return r == SignalRole::command || r == SignalRole::heartbeat || r == SignalRole::fault_reset ||
         r == SignalRole::window_start || r == SignalRole::window_length || r == SignalRole::calibration;
}

// Every signal of the kind, in documentation order.
std::span<const SignalSpec> signal_catalogue(DeviceKind k);
const SignalSpec* find_signal_spec(DeviceKind k, std::string_view signal);

}  // namespace synbench::drivers
