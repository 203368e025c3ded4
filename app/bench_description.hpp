// What the application knows of the bench it runs on, whatever the devices are: the safety
// limits its supervisor enforces, the setpoints an operator may ask for, the calibrations the
// analysis needs, and how often the bench is polled. A bench config's "limits" and
// "calibration" give it for real drives; for the in-process twin it follows the twin's config.
#pragma once

#include <optional>
#include <string>

#include "bench/safety_supervisor.hpp"
#include "drivers/uncertainty_config.hpp"

namespace synbench::app {

struct BenchDescription {
  bench::SafetyLimits limits;
  double max_speed_rpm = 1500.0;        // setpoints accepted from an operator or a plan
  double max_load_Nm = 10.0;
  double load_b1_Nms_per_rad = 2.0e-4;  // the load machine's viscous friction (shaft power)
  // A point's type B uncertainty inputs: the bench config's "uncertainty", the twin's defaults.
  drivers::UncertaintyConfig uncertainty;
  double poll_period_s = 0.01;          // telemetry reads of `synbench sweep` and `point`
  // The SynRM drive's profile name when it maps no temp_C: no winding temperature to run a
  // thermal precondition on (app/plan_needs.hpp).
  std::optional<std::string> synrm_without_temperature;
};

}  // namespace synbench::app
