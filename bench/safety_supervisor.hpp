// Safety supervisor of the bench: checked every tick, whatever a sweep is doing. On a limit
// violation, a device fault or a lost link it brings the bench to the ordered stop — load torque
// to zero, then speed to zero, then both drives disabled — and latches the reason until an
// explicit reset; an E-stop disables both drives at once. Every stop ends in the supervisor's own
// disable of both drives (each tried once before either is tried again), whose result is kept
// drive by drive (disable_report.hpp) and checked by reading the drives back: a drive whose
// disable was not acknowledged has it repeated at the start of every tick, before the tick's
// reads (on a starved line the reads may all time out first); one that acknowledged it but still
// reads running or cannot be read, at most every kDisableRepeat_s. A drive with a documented stop
// time (SynrmDrive::stop_time_s, a profile's stop_time_ms: an SS1-style ramp on the run bit), or
// that reads stopping, is ramping down: not repeated, and the loud alarm latches only when a
// drive still runs `stop_confirm_s` plus its stop time after the disable. Once a drive's disable
// went through, its setpoint (speed, load torque) is written to zero. Pure logic on the time it
// is given.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "bench/disable_report.hpp"
#include "bench/ordered_stop.hpp"
#include "bench/telemetry_plausibility.hpp"
#include "drivers/devices.hpp"

namespace synbench::bench {

struct SafetyLimits {
  double max_speed_rpm = 1650.0;
  double max_current_A = 5.0;
  double max_udc_V = 445.0;
  double min_udc_V = 320.0;      // checked only while a drive runs
  double max_temp_C = 110.0;
  double link_timeout_s = 0.5;   // telemetry reads failing this long is a lost link
  double stop_load_timeout_s = 1.0;   // step one of the ordered stop; then the load is disabled
  double stop_speed_timeout_s = 10.0; // step two, then disable regardless
  double stopped_speed_rpm = 20.0;
  // After a stop's disable, the drives must read back as not running within this long.
  double stop_confirm_s = 0.3;
  PlausibilityLimits plausibility;  // implausible_telemetry (telemetry_plausibility.hpp)
};

// The stricter of two sets of limits, each bound on its own (a plan may tighten the bench's).
SafetyLimits stricter(const SafetyLimits& a, const SafetyLimits& b);

// Why the bench stopped; `fault` names it with the device fault vocabulary.
struct SafetyTrip {
  drivers::Fault fault = drivers::Fault::none;
  std::string detail;   // e.g. "speed 1712 rpm > 1650 rpm"
  double at_s = 0;      // when it was detected
  std::optional<std::int64_t> fault_code_raw;  // a drive's code of an unknown fault
};

enum class SafetyPhase { normal, stopping_load, stopping_speed, stopped, estopped };

// A stop that did not take: a drive still reports running after its disable, or its state cannot
// be read back. Latched until a reset finds the drives stopped.
struct SafetyAlarm {
  std::string detail;  // "SynRM drive still reports running 0.30 s after its disable"
  double at_s = 0;
};

class SafetySupervisor {
 public:
  using EventSink = std::function<void(const std::string& kind, const std::string& message)>;

  SafetySupervisor(drivers::BenchDevices devices, SafetyLimits limits, EventSink sink = {});

  // Reads telemetry, checks limits, advances an ordered stop. Returns the telemetry it read (or
  // nothing when the link is down) so a sweep need not read twice.
  void tick(double now_s);
  const std::optional<drivers::SynrmTelemetry>& synrm() const { return synrm_; }
  const std::optional<drivers::LoadTelemetry>& load() const { return load_; }
  // Why this tick's read of a drive failed ("timeout (unit 1, input 0..19)"); empty when it was read.
  const std::string& synrm_read_error() const { return synrm_read_error_; }
  const std::string& load_read_error() const { return load_read_error_; }

  // Immediate disable of both drives (each request once: the caller's answer may follow at
  // once, disable_report() says what each drive made of it); latched like any trip.
  void estop(double now_s, const std::string& why = "E-stop");
  // Someone else's ordered stop (a user's disable, a sweep's end) has just disabled the drives:
  // the supervisor sends its own disable (harmless twice; so it knows each drive's answer) and
  // confirms it by reading them back, as after a trip.
  void expect_stopped(double now_s);
  // The last stop's disable, drive by drive; empty before the first stop and after a reset.
  const std::optional<DisableReport>& disable_report() const { return report_; }
  // Explicit reset: clears the latch and the devices' latched faults. Refused while an ordered
  // stop is still running, or while a drive still reads back running after a stop (errc::busy).
  // Never restarts anything.
  std::error_code reset();
  void set_limits(const SafetyLimits& limits) { lim_ = limits; }
  const SafetyLimits& limits() const { return lim_; }

  bool tripped() const { return trip_.has_value(); }
  bool may_command() const { return !trip_; }
  SafetyPhase phase() const { return phase_; }
  const std::optional<SafetyTrip>& trip() const { return trip_; }
  const std::optional<SafetyAlarm>& alarm() const { return alarm_; }
  // Set while a stop's disable is being confirmed by reading the drives back.
  bool confirming_stop() const { return confirming_; }
  // When the alarm is due if a drive still does not read back stopped: the later of the two
  // drives' (the disable + stop_confirm_s + the drive's documented stop time); empty when not
  // confirming.
  std::optional<double> stop_deadline_s() const;
  // Which drives the last read found running or could not read, in words ("the SynRM drive
  // still reports running"); empty when both read back off.
  std::string unconfirmed() const;
  // The SynRM drive's values the frozen-telemetry check cannot watch (their registers' steps are
  // coarser than a running drive's noise), for the record of what was supervised.
  std::vector<drivers::FrozenBlindSpot> frozen_blind_spots() const { return plausibility_.blind_spots(); }
  // Time from detection to both drives disabled, once the stop has completed.
  std::optional<double> stop_duration_s() const { return stop_duration_s_; }

 private:
  void raise(double now_s, drivers::Fault fault, std::string detail,
             std::optional<std::int64_t> fault_code_raw = std::nullopt);
  void advance_stop(double now_s);
  void disable_all(double now_s);
  void repeat_disables(double now_s);
  void confirm_stop(double now_s);
  void zero_setpoints();

  drivers::BenchDevices dev_;
  SafetyLimits lim_;
  EventSink sink_;
  std::optional<drivers::SynrmTelemetry> synrm_;
  std::optional<drivers::LoadTelemetry> load_;
  double last_good_read_s_ = 0;
  bool seen_good_read_ = false;
  SafetyPhase phase_ = SafetyPhase::normal;
  OrderedStop stop_;
  std::optional<SafetyTrip> trip_;
  std::optional<SafetyAlarm> alarm_;
  bool confirming_ = false;  // a stop's disable is being confirmed by reading the drives back
  std::optional<DisableReport> report_;
  std::string synrm_read_error_, load_read_error_;  // of this tick's reads
  std::optional<double> stop_duration_s_;
  TelemetryPlausibility plausibility_;
};

}  // namespace synbench::bench
