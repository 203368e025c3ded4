// The bench as the bench thread last saw it: setpoints, mode, telemetry, the supervisor's phase,
// trip and alarm, recent events and the sweep. Published once per tick as an immutable snapshot
// (BenchRuntime::snapshot), so readers never wait on device I/O.
#pragma once

#include <cstdint>
#include <deque>
#include <optional>
#include <string>

#include "bench/point_procedure.hpp"
#include "bench/safety_supervisor.hpp"
#include "drivers/devices.hpp"

namespace synbench::app {

struct Setpoints {
  double speed_rpm = 0;
  double load_Nm = 0;
  double angle_deg = 45;
};

// A change of some setpoints; the others keep their value.
struct SetpointsUpdate {
  std::optional<double> speed_rpm, load_Nm, angle_deg;
};

// The drive configuration manual operation runs with (a sweep sets its own per point).
struct DriveMode {
  drivers::Estimator estimator = drivers::Estimator::encoder;
  drivers::Pwm pwm = drivers::Pwm::capwm;
};

struct DriveModeUpdate {
  std::optional<drivers::Estimator> estimator;
  std::optional<drivers::Pwm> pwm;
};

struct BenchEvent {
  double t_s = 0;
  std::string kind, message;  // kind: fault, alarm, state, stop, enable, sweep, ...
  std::uint64_t seq = 0;      // 1, 2, 3, ... in order of occurrence: the WebSocket hub sends each once
};

// The sweep the bench thread runs (or ran last).
struct SweepInfo {
  std::int64_t id = 0;
  std::string state;  // bench::SweepState's name
  std::size_t done = 0, total = 0;
  std::string error;
  std::optional<std::size_t> current_index;     // the point being measured, while running
  std::optional<bench::PointRequest> point;     // its request (speed, load, angle, configuration)
};

struct BenchStatus {
  double t_s = 0;  // bench time since start
  bool enabled = false;
  bool stopping = false;  // an ordered stop asked for by disable or shutdown is under way
  bool heartbeats = true;  // false from an E-stop to the reset: the drives' watchdogs are armed
  Setpoints setpoints;  // the manual setpoints (kept for the next enable)
  // What the bench writes to the drives now, whoever writes it (manual operation, a sweep's point
  // with its load ramp, a stop): the last speed, load torque and angle each drive accepted.
  Setpoints commanded;
  DriveMode mode;
  std::optional<drivers::SynrmTelemetry> synrm;
  std::optional<drivers::LoadTelemetry> load;
  // Why the last read of a drive failed, while synrm or load is empty for it (else empty).
  std::string synrm_error, load_error;
  bench::SafetyPhase phase = bench::SafetyPhase::normal;
  std::optional<bench::SafetyTrip> trip;
  std::optional<bench::SafetyAlarm> alarm;
  std::optional<bench::DisableReport> disable;  // the last stop's disable, per drive, until a reset
  std::uint64_t ticks = 0;
  std::uint64_t overruns = 0;  // ticks that started more than one period late
  std::deque<BenchEvent> events;  // the most recent supervisor and command events
  std::optional<SweepInfo> sweep;
};

}  // namespace synbench::app
