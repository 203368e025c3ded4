// What a sweep plan needs of the bench beyond the signals every profile maps, checked before the
// sweep starts: a plan with a thermal precondition warms or cools the machine towards a winding
// temperature, which a drive without a temperature signal cannot report. Starting anyway would
// warm at the plan's warm-up load for up to its timeout, blind.
#pragma once

#include <optional>
#include <string>

#include "app/bench_description.hpp"
#include "bench/sweep_plan.hpp"

namespace synbench::app {

// Why `plan` cannot run on the bench `d` describes, naming the missing signal; empty if it can.
inline std::optional<std::string> unmet_plan_needs(const bench::SweepPlan& plan, const BenchDescription& d) {
  if (plan.thermal.enabled && d.synrm_without_temperature)
    return "the plan's thermal precondition (/thermal/enabled) needs the winding temperature, and the SynRM "
           "drive's profile '" +
           *d.synrm_without_temperature +
           "' maps no temp_C signal: map temp_C, or set \"thermal\": {\"enabled\": false}";
  return std::nullopt;
}

}  // namespace synbench::app
