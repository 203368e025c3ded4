// What a sweep's stored points say about its "measure until sure" options (docs/sweep-plan.md,
// "Outcome"): per adaptive curve the points used, the MTPA and ME angles with the uncertainties
// reached and whether the target was met, against the points the thesis grid's 2-deg steps over
// the bracket would have used; with a precision target, how many points missed it. Computed from
// the plan and the stored records only (the searches replayed as a resume replays them), so the
// command line, the daemon and a resumed sweep all say the same. Pure logic.
#pragma once

#include "drivers/json_fwd.hpp"

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "bench/point_record.hpp"
#include "bench/sweep_plan.hpp"
#include "bench/sweep_presets.hpp"  // kThesisAngleStep_deg, against which a search is counted

namespace synbench::bench {

// A group's search with the stored points of its evaluations 0, 1, ... reported in order, up to
// the first one missing: where a resumed sweep continues.
AngleSearch replay_search(const SweepPlan& plan, const PlannedGroup& group,
                          const std::map<std::size_t, PointRecord>& stored);

struct AdaptiveCurveOutcome {
  PlannedGroup group;
  AngleSearchResult result;  // evaluations: the points used
  bool finished = false;     // the search proposes nothing more (target met, or the cap)
};

struct PrecisionOutcome {
  double target_W = 0;
  std::size_t points = 0;                 // stored points
  std::vector<std::size_t> missed;        // indices stored above the target (or without a u)
};

struct SweepOutcome {
  std::vector<AdaptiveCurveOutcome> curves;  // adaptive mode only
  std::optional<double> angle_u_target_deg;  // the plan's, if any
  std::size_t points_used = 0;               // adaptive: stored points over all curves
  std::size_t grid_points = 0;               // the same curves on the thesis grid's 2-deg steps
  std::optional<PrecisionOutcome> precision;
};

SweepOutcome sweep_outcome(const SweepPlan& plan, const std::map<std::size_t, PointRecord>& stored);
// {"adaptive": {...} or null, "precision": {...} or null}
synbench::Json to_json(const SweepOutcome& o);
// One line per curve and a summary line, for the command line.
std::string to_text(const SweepOutcome& o);

}  // namespace synbench::bench
