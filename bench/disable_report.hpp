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
  // Not acknowledged: repeated every tick. Acknowledged but read back running (past its stop
  // time) or unreadable: repeated at most every kDisableRepeat_s.
  repeating,
  confirmed,     // read back not running
  // Acknowledged and reading stopping within the drive's documented stop time: its own ramp
  // down (an SS1-style drive), progress; not repeated while it lasts.
  stopping,
};

// The shortest time between two disable requests to a drive that acknowledged the last one but
// still reads running (its ramp, or a drive that ignores it): a bounded rate, not every tick.
inline constexpr double kDisableRepeat_s = 0.1;

constexpr std::string_view name(DisableState s) {
  switch (s) {
    case DisableState::acknowledged: return "acknowledged";
    case DisableState::repeating: return "repeating";
    case DisableState::confirmed: return "confirmed";
    case DisableState::stopping: return "stopping";
  }
  return "?";
}

struct DriveDisable {
  bool first_acknowledged = false;  // the drive acknowledged the first request
  DisableState state = DisableState::acknowledged;
  int attempts = 0;                 // disable requests sent
  bool last_acknowledged = false;   // the drive acknowledged the last request
  double last_sent_s = 0;           // when the last request went out
  double deadline_s = 0;            // the alarm's: at_s + stop_confirm_s + the drive's stop time
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
