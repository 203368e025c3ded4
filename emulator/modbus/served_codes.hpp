// What the emulator serves for an enumerated signal (a drive's `state`, ...) in each of the
// twin's codes, when the profile has no number for some of them. A real drive's status word
// always shows something; for a drive state the map cannot show, the twin shows the nearest
// state it can (a fixed fallback table: stopping -> running, faulted -> disabled), or the
// number that reads as the profile's `otherwise`, never a made-up 0 that may read as another
// state. A drive state the map cannot show at all (`running`, `disabled` without a number, an
// `otherwise` or a fallback) is refused at start: the bench could not run that drive either.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/profile/device_profile.hpp"

namespace synbench::emulator {

// The state a drive state without a number falls back to ("" when none): stopping -> running
// (the machine still turns and draws current on its ramp), faulted -> disabled (gated off; the
// fault shows in fault_code).
std::string_view state_fallback(std::string_view label);

struct ServedCodes {
  // Device number served for each of the catalogue's codes (index = the bench's code); nullopt
  // where the profile has none and no fallback applies. Empty for a non-enumerated signal and
  // for a fault code (served as the bench's own number, which reads as fault `unknown`).
  std::vector<std::optional<double>> by_code;
  std::vector<std::string> warnings;  // a drive state served through its fallback
  std::vector<std::string> errors;    // a drive state the profile cannot show
};

ServedCodes served_codes(const drivers::DeviceProfile& profile, const drivers::ProfileSignal& s);

// The warnings and errors of every profile's served codes, for `synbench emulate` to print
// once at start (and refuse on an error).
struct ServedCodeNotes {
  std::vector<std::string> warnings;
  std::vector<std::string> errors;
};
ServedCodeNotes check_served_codes(const std::vector<drivers::DeviceProfile>& profiles);

}  // namespace synbench::emulator
