// Expansion of a sweep plan into points, its canonical JSON and the bench-time estimate.
// (Parsing is in sweep_plan_parse.cpp.)
#include "bench/sweep_plan.hpp"

#include "drivers/json.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace synbench::bench {
namespace {

using ojson = synbench::Json;

// One (speed, load, configuration) with the angle at a planned point.
struct Cell {
  double speed_rpm, load_Nm, angle_deg;
  std::size_t config;
  std::pair<std::size_t, std::size_t> group_key;  // (speed-load pair, configuration)
};

bool speed_allowed(const PlannedConfiguration& c, double speed_rpm) {
  return speed_rpm >= c.min_speed_rpm && (!c.max_speed_rpm || speed_rpm <= *c.max_speed_rpm);
}

// Visits the plan's cells in sweep order: nested loops in plan.order, outermost first. With
// operating points, the (speed, load) pairs form one loop at the place of whichever of speed and
// load comes first. Points a configuration's speed range excludes are skipped.
template <typename Visit>
void for_each_cell(const SweepPlan& plan, bool with_angles, Visit&& visit) {
  enum class Level { speed, load, pair, config, angle };
  const bool pairs = !plan.operating_points.empty();
  std::vector<Level> levels;
  std::vector<std::size_t> sizes;
  bool pair_placed = false;
  for (auto d : plan.order) {
    switch (d) {
      case SweepDimension::speed:
      case SweepDimension::load:
        if (pairs) {
          if (!pair_placed) {
            levels.push_back(Level::pair);
            sizes.push_back(plan.operating_points.size());
            pair_placed = true;
          }
        } else {
          levels.push_back(d == SweepDimension::speed ? Level::speed : Level::load);
          sizes.push_back(d == SweepDimension::speed ? plan.speeds_rpm.size() : plan.loads_Nm.size());
        }
        break;
      case SweepDimension::config:
        levels.push_back(Level::config);
        sizes.push_back(plan.configurations.size());
        break;
      case SweepDimension::angle:
        if (with_angles) {
          levels.push_back(Level::angle);
          sizes.push_back(plan.angles_deg.size());
        }
        break;
    }
  }
  for (auto n : sizes)
    if (n == 0) return;
  std::vector<std::size_t> idx(levels.size(), 0);
  for (;;) {
    std::size_t s = 0, l = 0, pr = 0, c = 0, a = 0;
    for (std::size_t k = 0; k < levels.size(); ++k) {
      switch (levels[k]) {
        case Level::speed: s = idx[k]; break;
        case Level::load: l = idx[k]; break;
        case Level::pair: pr = idx[k]; break;
        case Level::config: c = idx[k]; break;
        case Level::angle: a = idx[k]; break;
      }
    }
    Cell cell{};
    if (pairs) {
      cell.speed_rpm = plan.operating_points[pr].speed_rpm;
      cell.load_Nm = plan.operating_points[pr].load_Nm;
      cell.group_key = {pr, c};
    } else {
      cell.speed_rpm = plan.speeds_rpm[s];
      cell.load_Nm = plan.loads_Nm[l];
      cell.group_key = {s * plan.loads_Nm.size() + l, c};
    }
    cell.angle_deg = with_angles ? plan.angles_deg[a] : 0.0;
    cell.config = c;
    if (speed_allowed(plan.configurations[c], cell.speed_rpm)) visit(cell);
    // Odometer: the innermost level turns fastest.
    std::size_t k = levels.size();
    while (k > 0) {
      --k;
      if (++idx[k] < sizes[k]) break;
      idx[k] = 0;
      if (k == 0) return;
    }
    if (levels.empty()) return;
  }
}

ojson configuration_json(const PlannedConfiguration& c) {
  ojson j = ojson::object();
  j["estimator"] = std::string(drivers::name(c.configuration.estimator));
  j["pwm"] = std::string(drivers::name(c.configuration.pwm));
  j["min_speed_rpm"] = c.min_speed_rpm;
  j["max_speed_rpm"] = c.max_speed_rpm ? ojson(*c.max_speed_rpm) : ojson(nullptr);
  j["gate_average_s"] = c.gate_average_s ? ojson(*c.gate_average_s) : ojson(nullptr);
  return j;
}

}  // namespace

std::vector<double> inclusive_range(double from, double to, double step) {
  std::vector<double> out;
  if (!(step > 0) || !(from <= to) || !std::isfinite(from) || !std::isfinite(to)) return out;
  // 1e-6 of a step of slack, so 0.1-type steps that do not add up exactly in binary still reach
  // `to`; values are computed from the index, never by accumulation.
  const auto n = static_cast<std::size_t>(std::floor((to - from) / step + 1e-6)) + 1;
  out.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double v = from + static_cast<double>(i) * step;
    out.push_back(std::round(v * 1e9) / 1e9);
  }
  return out;
}

std::string_view name(SweepDimension d) {
  switch (d) {
    case SweepDimension::speed: return "speed";
    case SweepDimension::load: return "load";
    case SweepDimension::config: return "config";
    case SweepDimension::angle: return "angle";
  }
  return "?";
}

std::string_view name(SweepMode m) { return kSweepModeNames[static_cast<std::size_t>(m)]; }
std::string_view name(PrecisionMode m) { return kPrecisionModeNames[static_cast<std::size_t>(m)]; }

std::string order_name(const std::array<SweepDimension, 4>& order) {
  std::string s;
  for (auto d : order) s += (s.empty() ? "" : "-") + std::string(name(d));
  return s;
}

std::vector<PlannedGroup> plan_groups(const SweepPlan& plan) {
  std::vector<PlannedGroup> out;
  std::map<std::pair<std::size_t, std::size_t>, std::size_t> seen;
  for_each_cell(plan, false, [&](const Cell& c) {
    if (seen.emplace(c.group_key, out.size()).second)
      out.push_back({out.size(), c.speed_rpm, c.load_Nm, plan.configurations[c.config]});
  });
  return out;
}

std::vector<PlannedPoint> expand(const SweepPlan& plan) {
  std::vector<PlannedPoint> out;
  if (plan.mode != SweepMode::grid) return out;
  std::map<std::pair<std::size_t, std::size_t>, std::size_t> groups;
  for_each_cell(plan, true, [&](const Cell& c) {
    const auto g = groups.emplace(c.group_key, groups.size()).first->second;
    PointRequest r;
    r.speed_rpm = c.speed_rpm;
    r.load_Nm = c.load_Nm;
    r.angle_deg = c.angle_deg;
    r.estimator = plan.configurations[c.config].configuration.estimator;
    r.pwm = plan.configurations[c.config].configuration.pwm;
    r.window_s = plan.window_s;
    out.push_back({out.size(), r, g});
  });
  return out;
}

PlannedPoint adaptive_point(const SweepPlan& plan, const PlannedGroup& group, std::size_t evaluation,
                            double angle_deg) {
  PointRequest r;
  r.speed_rpm = group.speed_rpm;
  r.load_Nm = group.load_Nm;
  r.angle_deg = angle_deg;
  r.estimator = group.configuration.configuration.estimator;
  r.pwm = group.configuration.configuration.pwm;
  r.window_s = plan.window_s;
  return {group.group * plan.adaptive.max_evaluations + evaluation, r, group.group};
}

PointOptions point_options(const SweepPlan& plan) {
  PointOptions o;
  o.gate = plan.gate.bands;
  o.min_settle_s = plan.gate.min_settle_s;
  o.settle_timeout_s = plan.gate.timeout_s;
  return o;
}

double gate_average_s(const SweepPlan& plan, const Configuration& c) {
  for (const auto& pc : plan.configurations)
    if (pc.configuration == c && pc.gate_average_s) return *pc.gate_average_s;
  return plan.gate.bands.average_s;
}

PointOptions point_options(const SweepPlan& plan, const Configuration& c) {
  PointOptions o = point_options(plan);
  o.gate.average_s = gate_average_s(plan, c);
  return o;
}

SafetyLimits safety_limits(const SweepPlan& plan) {
  SafetyLimits l;
  l.max_speed_rpm = plan.limits.max_speed_rpm;
  l.max_current_A = plan.limits.max_current_A;
  l.max_udc_V = plan.limits.max_udc_V;
  l.min_udc_V = plan.limits.min_udc_V;
  l.max_temp_C = plan.limits.max_temp_C;
  return l;
}

ojson to_json(const SweepPlan& p) {
  ojson j = ojson::object();
  j["name"] = p.name;
  if (!p.preset.empty()) j["preset"] = p.preset;
  j["mode"] = std::string(name(p.mode));
  j["order"] = order_name(p.order);
  ojson d = ojson::object();
  if (p.operating_points.empty()) {
    d["speed_rpm"] = p.speeds_rpm;
    d["load_Nm"] = p.loads_Nm;
  } else {
    ojson ops = ojson::array();
    for (const auto& op : p.operating_points) {
      ojson o = ojson::object();
      o["speed_rpm"] = op.speed_rpm;
      o["load_Nm"] = op.load_Nm;
      if (!op.label.empty()) o["label"] = op.label;
      ops.push_back(o);
    }
    d["operating_points"] = ops;
  }
  if (p.mode == SweepMode::grid) d["angle_deg"] = p.angles_deg;
  ojson cs = ojson::array();
  for (const auto& c : p.configurations) cs.push_back(configuration_json(c));
  d["configurations"] = cs;
  j["dimensions"] = d;
  if (p.mode == SweepMode::adaptive) {
    const auto& a = p.adaptive;
    j["adaptive"] = {{"bracket_deg", {a.from_deg, a.to_deg}},
                     {"tolerance_deg", a.tolerance_deg},
                     {"max_evaluations", a.max_evaluations},
                     {"stencil_deg", a.stencil_deg},
                     {"resolution_deg", a.resolution_deg},
                     {"angle_u_target_deg", a.angle_u_target_deg ? ojson(*a.angle_u_target_deg) : ojson(nullptr)}};
  }
  const auto& g = p.gate;
  j["gate"] = {{"span_s", g.bands.span_s},
               {"speed_band_rpm", g.bands.speed_band_rpm},
               {"im_band_rel", g.bands.im_band_rel},
               {"im_band_min_A", g.bands.im_band_min_A},
               {"power_band_rel", g.bands.power_band_rel},
               {"power_band_min_W", g.bands.power_band_min_W},
               {"average_s", g.bands.average_s},
               {"min_settle_s", g.min_settle_s},
               {"timeout_s", g.timeout_s}};
  j["window_s"] = p.window_s;
  if (p.precision) {
    j["precision"] = {{"pdcm_u_repeat_target_W", p.precision->pdcm_u_repeat_target_W},
                      {"max_window_s", p.precision->max_window_s},
                      {"mode", std::string(name(p.precision->mode))}};
  }
  const auto& t = p.thermal;
  j["thermal"] = {{"enabled", t.enabled},
                  {"target_C", t.target_C},
                  {"band_C", t.band_C},
                  {"warmup_load_Nm", t.warmup_load_Nm},
                  {"warmup_speed_rpm", t.warmup_speed_rpm ? ojson(*t.warmup_speed_rpm) : ojson(nullptr)},
                  {"timeout_s", t.timeout_s}};
  const auto& l = p.limits;
  j["limits"] = {{"max_speed_rpm", l.max_speed_rpm}, {"max_load_Nm", l.max_load_Nm},
                 {"max_current_A", l.max_current_A}, {"max_udc_V", l.max_udc_V},
                 {"min_udc_V", l.min_udc_V},         {"max_temp_C", l.max_temp_C}};
  j["notes"] = p.notes;
  return j;
}

SweepEstimate estimate(const SweepPlan& plan, const SweepTimeModel& m) {
  SweepEstimate e;
  struct Step {
    double speed_rpm, load_Nm;
    Configuration config;
  };
  std::vector<Step> steps;
  const auto groups = plan_groups(plan);
  e.groups = groups.size();
  if (plan.mode == SweepMode::grid) {
    for (const auto& p : expand(plan))
      steps.push_back({p.request.speed_rpm, p.request.load_Nm, {p.request.estimator, p.request.pwm}});
  } else {
    e.upper_bound = true;
    for (const auto& g : groups)
      for (std::size_t k = 0; k < plan.adaptive.max_evaluations; ++k)
        steps.push_back({g.speed_rpm, g.load_Nm, g.configuration.configuration});
  }
  e.points = steps.size();
  // The gate needs its span of (averaged) samples before it can pass.
  auto per_point_s = [&](const Configuration& c) {
    const double gate_s = plan.gate.bands.span_s + gate_average_s(plan, c);
    return std::max(plan.gate.min_settle_s, gate_s) + plan.window_s + m.point_overhead_s;
  };
  const auto ordered_stop_s = [&](double speed_rpm, double load_Nm) {
    return load_Nm / m.load_ramp_Nm_per_s + speed_rpm / m.speed_ramp_rpm_per_s + m.stop_s;
  };
  double speed = 0, load = 0, t = 0;
  bool standstill = true;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const auto& s = steps[i];
    if (i > 0) {
      if (s.speed_rpm != steps[i - 1].speed_rpm) ++e.speed_changes;
      if (s.load_Nm != steps[i - 1].load_Nm) ++e.load_changes;
      if (!(s.config == steps[i - 1].config)) {
        ++e.configuration_changes;
        t += ordered_stop_s(speed, load);
        speed = load = 0;
        standstill = true;
      }
    }
    const double speed_ramp_s = std::fabs(s.speed_rpm - speed) / m.speed_ramp_rpm_per_s;
    const double load_ramp_s = std::fabs(s.load_Nm - load) / m.load_ramp_Nm_per_s;
    if (standstill) t += speed_ramp_s + load_ramp_s + m.ramp_settle_s;  // spin-up, then the load
    else if (speed_ramp_s > 0 || load_ramp_s > 0) t += std::max(speed_ramp_s, load_ramp_s) + m.ramp_settle_s;
    else t += m.angle_settle_s;
    t += per_point_s(s.config);
    if (plan.precision) {
      // Measured again on the running bench: the gate's span, then a window of at most the cap.
      const double again_s = plan.gate.bands.span_s + gate_average_s(plan, s.config) +
                             plan.precision->max_window_s + m.point_overhead_s;
      e.precision_extra_s += static_cast<double>(kMaxPrecisionRemeasures) * again_s;
    }
    speed = s.speed_rpm;
    load = s.load_Nm;
    standstill = false;
  }
  if (!steps.empty()) t += ordered_stop_s(speed, load);  // back to standstill at the end
  e.bench_time_s = t + e.precision_extra_s;
  if (plan.precision) e.upper_bound = true;
  return e;
}

ojson to_json(const SweepEstimate& e) {
  ojson j = ojson::object();
  j["points"] = e.points;
  j["upper_bound"] = e.upper_bound;
  j["groups"] = e.groups;
  j["speed_changes"] = e.speed_changes;
  j["load_changes"] = e.load_changes;
  j["configuration_changes"] = e.configuration_changes;
  j["bench_time_s"] = e.bench_time_s;
  j["precision_extra_s"] = e.precision_extra_s;
  return j;
}

}  // namespace synbench::bench
