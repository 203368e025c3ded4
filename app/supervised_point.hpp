// One operating point run to its end under the safety supervisor, on any bench backend: what
// `synbench point` measures with, on the twin or on drives over Modbus. The supervisor reads the
// drives every tick and, on a limit, fault or lost link, takes over with its ordered stop; a
// point that fails on a device error ends with the ordered stop too, so no path leaves a drive
// running; and the end of every path is confirmed by reading both drives back.
#pragma once

#include <optional>

#include "app/bench_backend.hpp"
#include "bench/point_procedure.hpp"
#include "bench/safety_supervisor.hpp"

namespace synbench::app {

struct SupervisedPoint {
  bench::PointProcedure procedure;
  std::optional<bench::SafetyTrip> trip;    // the supervisor tripped during the point
  std::optional<bench::SafetyAlarm> alarm;  // a drive did not read back stopped at the end
  bool stopped_after_failure = false;       // the point failed and the bench was stopped in order
};

SupervisedPoint run_supervised_point(BenchBackend& backend, bench::SafetySupervisor& supervisor,
                                     const bench::PointRequest& request, const bench::PointOptions& options);

// Ticks the supervisor every `tick_s` from `now_s` until its confirmation that both drives read
// back stopped is over (confirmed, or its alarm raised). Returns the time reached.
double confirm_stopped(BenchBackend& backend, bench::SafetySupervisor& supervisor, double now_s, double tick_s);

}  // namespace synbench::app
