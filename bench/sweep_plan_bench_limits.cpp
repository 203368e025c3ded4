// A sweep plan against the bench's setpoint limits; see sweep_plan_bench_limits.hpp.
#include "bench/sweep_plan_bench_limits.hpp"

#include <algorithm>
#include <cstdio>
#include <string>

namespace synbench::bench {
namespace {

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

std::vector<SweepPlanError> check_bench_limits(const SweepPlan& plan, const BenchSetpointLimits& bench,
                                               bool dimensions_from_preset) {
  std::vector<SweepPlanError> out;
  const auto over = [&](const std::string& pointer, double value, double limit, const char* unit, const char* what) {
    if (value > limit)
      out.push_back({pointer, num(value) + " " + unit + " exceeds the bench's " + what + " (" + num(limit) + " " + unit +
                                  ", GET /api/bench/config)"});
  };
  const std::string dims = dimensions_from_preset ? "/preset" : "/dimensions";
  if (plan.operating_points.empty()) {
    // One message per dimension, for its largest value: a range's every value is not the person's.
    if (!plan.speeds_rpm.empty())
      over(dimensions_from_preset ? dims : dims + "/speed_rpm", *std::max_element(plan.speeds_rpm.begin(), plan.speeds_rpm.end()),
           bench.max_speed_rpm, "rpm", "max_speed_rpm");
    if (!plan.loads_Nm.empty())
      over(dimensions_from_preset ? dims : dims + "/load_Nm", *std::max_element(plan.loads_Nm.begin(), plan.loads_Nm.end()),
           bench.max_load_Nm, "N m", "max_load_Nm");
  } else {
    for (std::size_t i = 0; i < plan.operating_points.size(); ++i) {
      const auto& op = plan.operating_points[i];
      const std::string at = dimensions_from_preset ? dims : dims + "/operating_points/" + std::to_string(i);
      over(dimensions_from_preset ? at : at + "/speed_rpm", op.speed_rpm, bench.max_speed_rpm, "rpm", "max_speed_rpm");
      over(dimensions_from_preset ? at : at + "/load_Nm", op.load_Nm, bench.max_load_Nm, "N m", "max_load_Nm");
    }
  }
  if (plan.thermal.enabled) {
    over("/thermal/warmup_load_Nm", plan.thermal.warmup_load_Nm, bench.max_load_Nm, "N m", "max_load_Nm");
    if (plan.thermal.warmup_speed_rpm)
      over("/thermal/warmup_speed_rpm", *plan.thermal.warmup_speed_rpm, bench.max_speed_rpm, "rpm", "max_speed_rpm");
  }
  return out;
}

}  // namespace synbench::bench
