// A sweep plan: what a measurement campaign measures and how (docs/sweep-plan.md). Parsed from
// JSON with every problem reported at its JSON pointer, expanded into a deterministic list of
// points whose index is the resume key stored in the database, and written back as canonical
// JSON (stored with the sweep). Pure logic: no I/O besides the JSON given, no clock.
#pragma once

#include "drivers/json_fwd.hpp"
#include "drivers/json_reader.hpp"

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bench/load_ramp.hpp"
#include "bench/point_procedure.hpp"
#include "bench/safety_supervisor.hpp"
#include "bench/steady_state.hpp"
#include "bench/sweep_plan_angle_search.hpp"
#include "bench/sweep_plan_configuration.hpp"

namespace synbench::bench {

// A configuration as planned: measured only at speeds within [min_speed_rpm, max_speed_rpm]
// (the thesis measured the EEMF variants only from 500 rpm).
struct PlannedConfiguration {
  Configuration configuration;
  double min_speed_rpm = 0;
  std::optional<double> max_speed_rpm;  // none: no upper restriction
  std::optional<double> gate_average_s;  // replaces the plan's gate.average_s for these points
  bool operator==(const PlannedConfiguration&) const = default;
};

// One (speed, load) pair given explicitly, for point sets that are not a speed x load grid
// (the IEC 61800-9-2 points).
struct OperatingPoint {
  double speed_rpm = 0;
  double load_Nm = 0;
  std::string label;  // e.g. "IEC 61800-9-2 (50 %, 25 %)"; may be empty
  bool operator==(const OperatingPoint&) const = default;
};

enum class SweepDimension { speed, load, config, angle };
enum class SweepMode { grid, adaptive };
inline constexpr std::array<std::string_view, 2> kSweepModeNames{"grid", "adaptive"};  // by value

// The steady-state gate of every point: bands and slopes (SteadyStateBands), the least settling
// time after the load is applied, and the timeout after which the point is measured anyway and
// recorded as unstable (never dropped).
struct GateOptions {
  SteadyStateBands bands;
  double min_settle_s = 0.5;
  double timeout_s = 30.0;
  bool operator==(const GateOptions&) const = default;
};

// Thermal precondition: measure only with the winding within target_C +/- band_C. Below it the
// sweep warms the machine with warmup_load_Nm (at warmup_speed_rpm, or at the next point's speed
// when none); above it, it waits unloaded. timeout_s bounds one wait.
struct ThermalOptions {
  bool enabled = true;
  double target_C = 50.0;
  double band_C = 5.0;
  double warmup_load_Nm = 3.5;
  std::optional<double> warmup_speed_rpm;
  double timeout_s = 3600.0;
  bool operator==(const ThermalOptions&) const = default;
};

// Limits of the run. The first five match bench::SafetyLimits' meaning and defaults; the plan's
// setpoints are checked against max_speed_rpm and max_load_Nm when it is parsed.
struct SweepLimits {
  double max_speed_rpm = 1650.0;
  double max_current_A = 5.0;
  double max_udc_V = 445.0;
  double min_udc_V = 320.0;
  double max_temp_C = 110.0;
  double max_load_Nm = 3.5;  // rated torque of the SynRM
  bool operator==(const SweepLimits&) const = default;
};

// "Measure until sure" (docs/sweep-plan.md, "Precision"): a point whose pdcm_u_repeat_W (the
// point-to-point part of P_dcM's standard uncertainty, which limits comparing the points of one
// curve; the systematic rest is common to them and no window length reduces it) is above the
// target is measured again, drives kept running, over a longer window predicted from
// u ~ window^-1/2 and capped at max_window_s; only the last record is stored, at the point's
// own index. A point that cannot reach the target within the cap is stored with what it reached
// and flagged (an event, a count in the sweep's outcome).
enum class PrecisionMode { lengthen };
inline constexpr std::array<std::string_view, 1> kPrecisionModeNames{"lengthen"};  // by value
struct PrecisionOptions {
  double pdcm_u_repeat_target_W = 0.05;
  double max_window_s = 8.0;
  PrecisionMode mode = PrecisionMode::lengthen;
  bool operator==(const PrecisionOptions&) const = default;
};
// At most this many windows after the first: the predicted one, then the cap.
inline constexpr std::size_t kMaxPrecisionRemeasures = 2;

inline constexpr std::array<SweepDimension, 4> kDefaultOrder{SweepDimension::speed, SweepDimension::load,
                                                             SweepDimension::config, SweepDimension::angle};

struct SweepPlan {
  std::string name;
  std::string preset;  // the preset the plan was built from ("" when none); informational
  // Grid dimensions. speeds_rpm x loads_Nm unless operating_points is not empty, which then
  // replaces both. angles_deg is empty in adaptive mode (the search picks the angles).
  std::vector<double> speeds_rpm, loads_Nm, angles_deg;
  std::vector<OperatingPoint> operating_points;
  std::vector<PlannedConfiguration> configurations;
  std::array<SweepDimension, 4> order = kDefaultOrder;  // outermost first
  SweepMode mode = SweepMode::grid;
  AngleSearchOptions adaptive;  // used in adaptive mode
  GateOptions gate;
  double window_s = 1.0;
  std::optional<PrecisionOptions> precision;  // none: every point measured once over window_s
  ThermalOptions thermal;
  SweepLimits limits;
  std::vector<std::string> notes;  // how the plan was built, e.g. how a preset treats a point
  bool operator==(const SweepPlan&) const = default;
};

// One problem in a plan document: RFC 6901 JSON pointer ("" for the whole document) and
// reason; drivers::to_string(e) gives "/dimensions/speed_rpm/1: must be > 0".
using SweepPlanError = drivers::JsonError;
using drivers::to_string;

struct SweepPlanParseResult {
  std::optional<SweepPlan> plan;        // set exactly when errors is empty
  std::vector<SweepPlanError> errors;   // every problem, not only the first
};

SweepPlanParseResult parse_sweep_plan(const synbench::Json& doc);

// Canonical form: every field explicit (defaults filled in, ranges and presets expanded into
// lists) in a fixed key order. parse_sweep_plan(to_json(p)) gives p back.
synbench::Json to_json(const SweepPlan& plan);

// The (speed, load, configuration) curves of a plan, numbered in sweep order. An adaptive search
// works on one group; in grid mode a group is the angle sweep at one (speed, load, config).
struct PlannedGroup {
  std::size_t group = 0;
  double speed_rpm = 0;
  double load_Nm = 0;
  PlannedConfiguration configuration;
};

struct PlannedPoint {
  std::size_t index;      // position in the sweep; the resume key stored with the measured point
  PointRequest request;
  std::size_t group;      // PlannedGroup::group of its (speed, load, configuration)
};

// Groups in sweep order (both modes).
std::vector<PlannedGroup> plan_groups(const SweepPlan& plan);

// Grid mode: every point in sweep order, index 0, 1, 2, ... Adaptive mode: empty (the angles are
// not known in advance); use plan_groups() and adaptive_point().
std::vector<PlannedPoint> expand(const SweepPlan& plan);

// Adaptive mode: the request for evaluation `evaluation` (0-based, < adaptive.max_evaluations)
// of a group at the angle the search proposed. index = group * max_evaluations + evaluation,
// so indices grow in sweep order and stay stable however many points a search needs.
PlannedPoint adaptive_point(const SweepPlan& plan, const PlannedGroup& group, std::size_t evaluation,
                            double angle_deg);

// The point procedure's options for this plan's gate (other fields keep PointOptions' defaults);
// with a configuration, its gate_average_s replaces the plan's where it has one.
PointOptions point_options(const SweepPlan& plan);
PointOptions point_options(const SweepPlan& plan, const Configuration& c);
// The gate's averaging time for a configuration's points: its own, else the plan's.
double gate_average_s(const SweepPlan& plan, const Configuration& c);

// The safety supervisor's limits from the plan's (those SafetyLimits has).
SafetyLimits safety_limits(const SweepPlan& plan);

// Bench-time model (docs/sweep-plan.md), after what the engine does with the drives kept running
// between points (PointOptions::continue_running), fitted to real-time twin sweeps under
// `synbench serve`:
// - every point: the gate, max(min_settle_s, span_s + the configuration's average_s), then the
//   window and point_overhead_s (commands and the window's results, a few 10 ms ticks);
// - before it, what changed since the last point: a speed and / or load change ramps both at
//   once (the firmware's speed ramp, the bench's own load ramp, bench/load_ramp.hpp) and the
//   3 Hz speed loop then needs ramp_settle_s to come into the gate's 2 rpm band; an angle-only
//   step needs angle_settle_s (on average: a few degrees cost nothing, 10 deg about 0.5 s);
// - from standstill (the first point, and after each configuration change) the spin-up and the
//   load ramp one after the other, then ramp_settle_s;
// - an ordered stop at each configuration change (the engine stops the drives to switch
//   estimator or PWM) and at the end: the load ramped off, the speed ramped down, stop_s to
//   confirm both stopped.
// Thermal waits and gate timeouts are not included: they depend on the machine's state.
struct SweepTimeModel {
  double speed_ramp_rpm_per_s = 1000.0;                // firmware speed ramp
  double load_ramp_Nm_per_s = kBenchLoadRamp_Nm_per_s;  // the bench ramps the load setpoint
  double ramp_settle_s = 0.7;                          // speed loop after a speed / load ramp
  double angle_settle_s = 0.25;                        // after an angle-only step
  double point_overhead_s = 0.1;                       // commands, the window's results
  double stop_s = 0.2;                                 // the ordered stop's confirmation
};

struct SweepEstimate {
  std::size_t points = 0;        // adaptive: groups x max_evaluations, an upper bound
  std::size_t groups = 0;
  std::size_t speed_changes = 0;
  std::size_t load_changes = 0;
  std::size_t configuration_changes = 0;
  double bench_time_s = 0;
  bool upper_bound = false;      // true in adaptive mode and with a precision target
  // With a precision target: the bench time the longer windows may add at most (included in
  // bench_time_s: every point measured kMaxPrecisionRemeasures more times, over max_window_s).
  double precision_extra_s = 0;
};

SweepEstimate estimate(const SweepPlan& plan, const SweepTimeModel& model = {});
synbench::Json to_json(const SweepEstimate& e);

// from, from + step, ..., to: inclusive, each value computed as from + i * step (no accumulated
// error) and rounded to 1e-9, with `to` included when it lies within 1e-6 steps of the grid.
// Empty for step <= 0 or from > to.
std::vector<double> inclusive_range(double from, double to, double step);

std::string_view name(SweepDimension d);
std::string_view name(SweepMode m);
std::string_view name(PrecisionMode m);
// "speed-load-config-angle"
std::string order_name(const std::array<SweepDimension, 4>& order);

}  // namespace synbench::bench
