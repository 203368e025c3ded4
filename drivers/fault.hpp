// Fault codes a drive reports. Faults latch in the device until an explicit reset; a limit
// (voltage limit, current limit) is a flag on the measurement, never a fault.
#pragma once

#include <cstdint>
#include <optional>
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
  }
  return "unknown";
}

}  // namespace synbench::drivers
