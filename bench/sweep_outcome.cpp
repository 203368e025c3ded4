// Replaying the stored points of a sweep into its searches and counting what they used.
#include "bench/sweep_outcome.hpp"

#include "drivers/json.hpp"

#include <cstdio>

namespace synbench::bench {
namespace {

using ojson = synbench::Json;

ojson optional_number(const std::optional<double>& v) { return v ? ojson(*v) : ojson(nullptr); }

ojson optimum_json(const AngleOptimum& o) {
  return {{"angle_deg", o.angle_deg},
          {"angle_u_deg", optional_number(o.angle_u_deg)},
          {"refined", o.refined},
          {"at_edge", o.at_edge},
          {"points_in_fit", o.points_used}};
}

std::string u_text(const std::optional<double>& u) {
  if (!u) return "u unknown";
  char buf[32];
  std::snprintf(buf, sizeof buf, "u %.2f deg", *u);
  return buf;
}

}  // namespace

AngleSearch replay_search(const SweepPlan& plan, const PlannedGroup& group,
                          const std::map<std::size_t, PointRecord>& stored) {
  AngleSearch search(plan.adaptive);
  for (std::size_t e = 0; e < plan.adaptive.max_evaluations; ++e) {
    const auto it = stored.find(group.group * plan.adaptive.max_evaluations + e);
    if (it == stored.end()) break;
    const PointRecord& r = it->second;
    // The point-to-point parts: what scatters between the points of one curve (the systematic
    // rest moves every point alike and no angle with them).
    search.report(r.angle_deg, r.im_A, r.pdcm_W, r.im_u_repeat_A, r.pdcm_u_repeat_W);
  }
  return search;
}

SweepOutcome sweep_outcome(const SweepPlan& plan, const std::map<std::size_t, PointRecord>& stored) {
  SweepOutcome o;
  if (plan.mode == SweepMode::adaptive) {
    o.angle_u_target_deg = plan.adaptive.angle_u_target_deg;
    const std::size_t grid_angles =
        inclusive_range(plan.adaptive.from_deg, plan.adaptive.to_deg, kThesisAngleStep_deg).size();
    for (const auto& g : plan_groups(plan)) {
      const AngleSearch search = replay_search(plan, g, stored);
      if (search.evaluations().empty()) continue;  // not reached yet
      o.curves.push_back({g, search.result(), search.finished()});
      o.points_used += search.evaluations().size();
      o.grid_points += grid_angles;
    }
  }
  if (plan.precision) {
    PrecisionOutcome p;
    p.target_W = plan.precision->pdcm_u_repeat_target_W;
    for (const auto& [index, r] : stored) {
      ++p.points;
      if (!r.pdcm_u_repeat_W || *r.pdcm_u_repeat_W > p.target_W) p.missed.push_back(index);
    }
    o.precision = std::move(p);
  }
  return o;
}

ojson to_json(const SweepOutcome& o) {
  ojson j = ojson::object();
  if (o.curves.empty()) {
    j["adaptive"] = nullptr;
  } else {
    ojson curves = ojson::array();
    std::size_t met = 0;
    for (const auto& c : o.curves) {
      met += c.result.angle_u_target_met;
      curves.push_back({{"group", c.group.group},
                        {"speed_rpm", c.group.speed_rpm},
                        {"load_Nm", c.group.load_Nm},
                        {"configuration", label(c.group.configuration.configuration)},
                        {"points_used", c.result.evaluations},
                        {"finished", c.finished},
                        {"angle_u_target_met", c.result.angle_u_target_met},
                        {"mtpa", optimum_json(c.result.mtpa)},
                        {"me", optimum_json(c.result.me)}});
    }
    j["adaptive"] = {{"curves", curves},
                     {"points_used", o.points_used},
                     {"grid_points", o.grid_points},
                     {"grid_step_deg", kThesisAngleStep_deg},
                     {"angle_u_target_deg", optional_number(o.angle_u_target_deg)},
                     {"curves_target_met", met}};
  }
  if (o.precision) {
    j["precision"] = {{"pdcm_u_repeat_target_W", o.precision->target_W},
                      {"points", o.precision->points},
                      {"points_missed", o.precision->missed.size()},
                      {"missed_indices", o.precision->missed}};
  } else {
    j["precision"] = nullptr;
  }
  return j;
}

std::string to_text(const SweepOutcome& o) {
  std::string out;
  char line[400];
  for (const auto& c : o.curves) {
    std::snprintf(line, sizeof line,
                  "curve %zu (%.0f rpm, %.3g N m, %s): %zu points, MTPA %.2f deg (%s), ME %.2f deg (%s)%s\n",
                  c.group.group, c.group.speed_rpm, c.group.load_Nm, label(c.group.configuration.configuration).c_str(),
                  c.result.evaluations, c.result.mtpa.angle_deg, u_text(c.result.mtpa.angle_u_deg).c_str(),
                  c.result.me.angle_deg, u_text(c.result.me.angle_u_deg).c_str(),
                  !o.angle_u_target_deg          ? ""
                  : c.result.angle_u_target_met ? ", target met"
                  : c.finished                  ? ", target not met within max_evaluations"
                                                : "");
    out += line;
  }
  if (!o.curves.empty()) {
    std::snprintf(line, sizeof line, "adaptive: %zu points used against %zu on the %.0f-deg grid\n", o.points_used,
                  o.grid_points, kThesisAngleStep_deg);
    out += line;
  }
  if (o.precision) {
    std::snprintf(line, sizeof line, "precision: %zu of %zu points above pdcm_u_repeat_W %.3g W\n",
                  o.precision->missed.size(), o.precision->points, o.precision->target_W);
    out += line;
  }
  return out;
}

}  // namespace synbench::bench
