// What became of a stop's disable, drive by drive, from its first attempt to the read-back: what
// the E-stop's answer says and the bench status keeps saying until both drives read back
// stopped, so a client tells "disabled" from "disable sent, not confirmed". Kept by the safety
// supervisor, which sends every stop's disable itself (safety_supervisor.hpp).
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace synbench::bench {

enum class DisableState {
  acknowledged,  // the drive acknowledged the last disable request; not read back yet
  repeating,     // not acknowledged, or read back running or unreadable: repeated every tick
  confirmed,     // read back not running
};

constexpr std::string_view name(DisableState s) {
  switch (s) {
    case DisableState::acknowledged: return "acknowledged";
    case DisableState::repeating: return "repeating";
    case DisableState::confirmed: return "confirmed";
  }
  return "?";
}

struct DriveDisable {
  bool first_acknowledged = false;  // the drive acknowledged the first request
  DisableState state = DisableState::acknowledged;
  int attempts = 0;                 // disable requests sent
  std::string error;                // why it is not confirmed yet, in words; "" when nothing failed
  std::optional<double> confirmed_s;  // when it first read back not running
  // After the disable (never before it, never in its way) the drive's setpoint is written to
  // zero: the SynRM's speed, the load's torque. Tried each tick once the disable went through.
  bool setpoint_zeroed = false;
};

struct DisableReport {
  double at_s = 0;  // the first attempt
  DriveDisable synrm, load;
  bool confirmed() const { return synrm.state == DisableState::confirmed && load.state == DisableState::confirmed; }
};

}  // namespace synbench::bench
