// Fault codes a drive reports. Faults latch in the device until an explicit reset; a limit
// (voltage limit, current limit) is a flag on the measurement, never a fault.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace synbench::drivers {

enum class Fault : std::uint16_t {
  none = 0,
  overcurrent = 1,
  overvoltage = 2,
  undervoltage = 3,
  overspeed = 4,
  overtemperature = 5,
  watchdog = 6,
  estop = 7,
  link_loss = 8,
  load_drive = 9,
  // The bench's own verdict, never a drive's code: the safety supervisor found telemetry no
  // working drive reports (a value frozen bit for bit, current into a shaft at rest, a negative
  // magnitude); bench/telemetry_plausibility.hpp.
  implausible_telemetry = 10,
  // A device code its profile has no label for: a fault all the same (a drive that reports
  // something is not fine); the raw code travels with it (fault_code_raw).
  unknown = 11,
};

constexpr std::string_view fault_name(Fault f) {
  switch (f) {
    case Fault::none: return "none";
    case Fault::overcurrent: return "overcurrent";
    case Fault::overvoltage: return "overvoltage";
    case Fault::undervoltage: return "undervoltage";
    case Fault::overspeed: return "overspeed";
    case Fault::overtemperature: return "overtemperature";
    case Fault::watchdog: return "watchdog";
    case Fault::estop: return "estop";
    case Fault::link_loss: return "link_loss";
    case Fault::load_drive: return "load_drive";
    case Fault::implausible_telemetry: return "implausible_telemetry";
    case Fault::unknown: return "unknown";
  }
  return "unknown";
}

// For events and errors: the fault's name, and for an unknown one the device's code
// ("unknown fault (device code 8721)").
inline std::string describe_fault(Fault f, std::optional<std::int64_t> device_code) {
  if (f == Fault::unknown)
    return "unknown fault" + (device_code ? " (device code " + std::to_string(*device_code) + ")" : std::string());
  return std::string(fault_name(f));
}

}  // namespace synbench::drivers
