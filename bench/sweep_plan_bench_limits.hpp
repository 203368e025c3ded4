// A parsed sweep plan checked against the bench it is to run on: a plan's own limits
// (/limits, default 1650 rpm) may exceed what this bench's drives allow (the bench
// configuration's max_speed_rpm, e.g. 1500 rpm), and such a plan would fault at its first point
// past the drive's limit. The daemon refuses it at create and estimate, each problem at the JSON
// pointer of the setpoint the person wrote, naming the bench's limit.
#pragma once

#include <vector>

#include "bench/sweep_plan.hpp"

namespace synbench::bench {

struct BenchSetpointLimits {
  double max_speed_rpm = 0;
  double max_load_Nm = 0;
};

// Every planned setpoint above the bench's limits: grid speeds at /dimensions/speed_rpm, loads
// at /dimensions/load_Nm, operating points at /dimensions/operating_points/<i>/speed_rpm (or
// load_Nm), the thermal warm-up at /thermal/...; a preset's own values at /preset. Empty: fits.
std::vector<SweepPlanError> check_bench_limits(const SweepPlan& plan, const BenchSetpointLimits& bench,
                                               bool dimensions_from_preset);

}  // namespace synbench::bench
