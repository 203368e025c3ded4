// Parsing and validation of sweep plans. Every check names the JSON pointer of what it rejects
// and parsing goes on after a problem, so a user fixes a plan in one pass.
#include "drivers/json.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <initializer_list>
#include <set>
#include <sstream>

#include "bench/current_angle.hpp"
#include "bench/sweep_plan.hpp"
#include "bench/window_plausibility.hpp"
#include "bench/sweep_presets.hpp"

namespace synbench::bench {
namespace {

using json = synbench::Json;

using drivers::JsonNode;
using drivers::JsonReader;
using drivers::non_negative;
using drivers::positive;
using Check = drivers::NumberCheck;

constexpr std::size_t kMaxDimensionValues = 10000;  // a range with more is a typo, not a plan
constexpr std::size_t kMaxPoints = 1000000;

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string in_quotes(std::string_view s) { return "'" + std::string(s) + "'"; }

Check within(double lo, double hi, const char* unit) {
  return [=](double v) {
    return v >= lo && v <= hi ? std::string() : "must be within [" + num(lo) + ", " + num(hi) + "] " + unit;
  };
}
// (lo, hi]: a duration or a tolerance.
Check above_at_most(double lo, double hi, const char* unit) {
  return [=](double v) {
    return v > lo && v <= hi ? std::string() : "must be within (" + num(lo) + ", " + num(hi) + "] " + unit;
  };
}
Check positive_at_most(double hi, const std::string& what) {
  return [=](double v) {
    if (v <= 0) return std::string("must be > 0");
    if (v > hi) return num(v) + " exceeds " + what + " (" + num(hi) + ")";
    return std::string();
  };
}
Check non_negative_at_most(double hi, const std::string& what) {
  return [=](double v) {
    if (v < 0) return std::string("must be >= 0");
    if (v > hi) return num(v) + " exceeds " + what + " (" + num(hi) + ")";
    return std::string();
  };
}
Check angle_check() {
  return [](double v) {
    return is_motoring_angle(v) ? std::string() : "must be inside (0, 90) deg (the motoring region)";
  };
}

// Overwrites `out` when the node is present and valid.
void set(const JsonNode& n, double& out, const Check& check) {
  if (auto v = n.number(check)) out = *v;
}
// Same for an optional value, which null clears.
void set_or_clear(const JsonNode& n, std::optional<double>& out, const Check& check) {
  if (n.is_null()) out.reset();
  else if (auto v = n.number(check)) out = *v;
}

bool near(double a, double b) { return std::fabs(a - b) <= 1e-9 * std::max(1.0, std::fabs(b)); }

std::optional<std::vector<double>> range(const JsonNode& v, const Check& check);

// A dimension: a non-empty list of numbers or a range {from, to, step}. Every value is checked;
// duplicates are rejected (they would measure a point twice under two indices).
std::optional<std::vector<double>> dimension(const JsonNode& v, const Check& check) {
  if (v.present() && v.json().is_object()) return range(v, check);
  const auto items = v.list("must be a list of numbers or a range {\"from\", \"to\", \"step\"}", true);
  if (!items) return std::nullopt;
  if (items->size() > kMaxDimensionValues) {
    v.fail("has " + std::to_string(items->size()) + " values; at most " + std::to_string(kMaxDimensionValues));
    return std::nullopt;
  }
  std::vector<double> out;
  bool ok = true;
  for (const JsonNode& item : *items) {
    const auto x = item.number(check);
    if (!x) {
      ok = false;
      continue;
    }
    for (std::size_t j = 0; j < out.size(); ++j) {
      if (near(out[j], *x)) {
        item.fail("duplicate of " + v.pointer() + "/" + std::to_string(j) + " (" + num(*x) + ")");
        ok = false;
      }
    }
    out.push_back(*x);
  }
  if (!ok) return std::nullopt;
  return out;
}

std::optional<std::vector<double>> range(const JsonNode& v, const Check& check) {
  JsonReader& r = v.reader();
  v.reject_unknown({"from", "to", "step"});
  const std::size_t before = r.count();
  const auto from = v["from"].required().number(check);
  const auto to = v["to"].required().number(check);
  const auto step = v["step"].required().number(positive());
  if (r.count() != before || !from || !to || !step) return std::nullopt;
  if (*from > *to) {
    v["to"].fail("must be >= from (" + num(*from) + ")");
    return std::nullopt;
  }
  const double steps = (*to - *from) / *step;
  if (steps + 1 > static_cast<double>(kMaxDimensionValues)) {
    v["step"].fail("gives " + num(std::floor(steps) + 1) + " values; at most " + std::to_string(kMaxDimensionValues));
    return std::nullopt;
  }
  if (std::fabs(steps - std::round(steps)) > 1e-6) {
    const auto values = inclusive_range(*from, *to, *step);
    v["to"].fail(num(*to) + " is not reached from " + num(*from) + " in whole steps of " + num(*step) +
                 " (the last value would be " + num(values.back()) + ")");
    return std::nullopt;
  }
  return inclusive_range(*from, *to, *step);
}

std::optional<SweepDimension> parse_dimension(std::string_view s) {
  for (auto d : {SweepDimension::speed, SweepDimension::load, SweepDimension::config, SweepDimension::angle})
    if (name(d) == s) return d;
  return std::nullopt;
}

// "preset": "thesis-grid" or {"name": "iec-61800-9-2", "rated_speed_rpm": ..., ...}
SweepPlan preset_plan(const JsonNode& v) {
  std::string preset;
  const bool options = v.present() && v.json().is_object();
  if (v.json().is_string()) {
    preset = v.json().get<std::string>();
  } else if (options) {
    preset = v["name"].required().text().value_or("");
  } else {
    v.fail("must be a preset name or an object {\"name\": ...}");
    return SweepPlan{};
  }
  if (preset == kThesisGridPreset) {
    if (options) v.reject_unknown({"name"});
    return thesis_grid_plan();
  }
  if (preset == kIecPreset) {
    IecPresetOptions o;
    if (options) {
      v.reject_unknown({"name", "rated_speed_rpm", "rated_torque_Nm", "zero_speed_rpm"});
      set(v["rated_speed_rpm"], o.rated_speed_rpm, positive());
      set(v["rated_torque_Nm"], o.rated_torque_Nm, positive());
      set(v["zero_speed_rpm"], o.zero_speed_rpm, non_negative());
    }
    return iec_61800_9_2_plan(o);
  }
  if (!preset.empty() || !options)
    (options ? v["name"] : v).fail(JsonNode::unknown_choice("preset", preset, JsonNode::names_list(kPresetNames)));
  return SweepPlan{};
}

void parse_limits(const JsonNode& v, SweepLimits& l) {
  if (!v.object()) return;
  v.reject_unknown({"max_speed_rpm", "max_load_Nm", "max_current_A", "max_udc_V", "min_udc_V", "max_temp_C"});
  set(v["max_speed_rpm"], l.max_speed_rpm, positive());
  set(v["max_load_Nm"], l.max_load_Nm, positive());
  set(v["max_current_A"], l.max_current_A, positive());
  set(v["max_udc_V"], l.max_udc_V, positive());
  set(v["min_udc_V"], l.min_udc_V, non_negative());
  set(v["max_temp_C"], l.max_temp_C, within(-40, 250, "degC"));
  if (l.min_udc_V >= l.max_udc_V)
    v["min_udc_V"].fail(num(l.min_udc_V) + " must be below max_udc_V (" + num(l.max_udc_V) + ")");
}

void parse_configurations(const JsonNode& v, bool thesis_rules, std::vector<PlannedConfiguration>& out) {
  JsonReader& r = v.reader();
  const auto items = v.list("must be a list of {\"estimator\", \"pwm\"}", true);
  if (!items) return;
  std::vector<PlannedConfiguration> list;
  bool ok = true;
  for (const JsonNode& c : *items) {
    if (!c.object()) {
      ok = false;
      continue;
    }
    const std::size_t before = r.count();
    c.reject_unknown({"estimator", "pwm", "min_speed_rpm", "max_speed_rpm", "gate_average_s"});
    PlannedConfiguration pc;
    const auto est = c["estimator"].required().choice<drivers::Estimator>(drivers::kEstimatorNames, "estimator");
    const auto pwm = c["pwm"].required().choice<drivers::Pwm>(drivers::kPwmNames, "PWM scheme");
    if (est) pc.configuration.estimator = *est;
    if (pwm) pc.configuration.pwm = *pwm;
    if (thesis_rules) pc = with_thesis_defaults(pc.configuration);
    set(c["min_speed_rpm"], pc.min_speed_rpm, non_negative());
    set_or_clear(c["max_speed_rpm"], pc.max_speed_rpm, positive());
    set_or_clear(c["gate_average_s"], pc.gate_average_s, non_negative());
    if (pc.max_speed_rpm && *pc.max_speed_rpm < pc.min_speed_rpm)
      c["max_speed_rpm"].fail("must be >= min_speed_rpm (" + num(pc.min_speed_rpm) + ")");
    if (r.count() != before) {
      ok = false;
      continue;
    }
    for (std::size_t j = 0; j < list.size(); ++j) {
      if (list[j].configuration == pc.configuration) {
        c.fail("duplicate of " + v.pointer() + "/" + std::to_string(j) + " (" + label(pc.configuration) + ")");
        ok = false;
      }
    }
    list.push_back(pc);
  }
  if (ok) out = std::move(list);
}

void parse_operating_points(const JsonNode& v, const SweepLimits& lim, std::vector<OperatingPoint>& out) {
  JsonReader& r = v.reader();
  const auto items = v.list("must be a list of {\"speed_rpm\", \"load_Nm\"}", true);
  if (!items) return;
  std::vector<OperatingPoint> list;
  bool ok = true;
  for (const JsonNode& o : *items) {
    if (!o.object()) {
      ok = false;
      continue;
    }
    const std::size_t before = r.count();
    o.reject_unknown({"speed_rpm", "load_Nm", "label"});
    o["speed_rpm"].required();
    o["load_Nm"].required();
    OperatingPoint pt;
    set(o["speed_rpm"], pt.speed_rpm, positive_at_most(lim.max_speed_rpm, "/limits/max_speed_rpm"));
    set(o["load_Nm"], pt.load_Nm, non_negative_at_most(lim.max_load_Nm, "/limits/max_load_Nm"));
    if (auto s = o["label"].text()) pt.label = *s;
    if (r.count() != before) {
      ok = false;
      continue;
    }
    for (std::size_t j = 0; j < list.size(); ++j) {
      if (list[j].speed_rpm == pt.speed_rpm && list[j].load_Nm == pt.load_Nm) {
        o.fail("duplicate of " + v.pointer() + "/" + std::to_string(j));
        ok = false;
      }
    }
    list.push_back(pt);
  }
  if (ok) out = std::move(list);
}

void parse_dimensions(const JsonNode& d, SweepPlan& plan, bool has_preset) {
  const bool grid = plan.mode == SweepMode::grid;
  if (plan.mode == SweepMode::adaptive) plan.angles_deg.clear();
  if (!d.present()) {
    if (!has_preset) d.fail("required field is missing (or name a preset)");
    return;
  }
  if (!d.object()) return;
  d.reject_unknown({"speed_rpm", "load_Nm", "angle_deg", "operating_points", "configurations"});
  const auto& lim = plan.limits;

  const bool has_speed = d.has("speed_rpm"), has_load = d.has("load_Nm");
  if (d.has("operating_points")) {
    if (has_speed || has_load) {
      d["operating_points"].fail("cannot be combined with speed_rpm and load_Nm (it replaces both)");
    } else {
      plan.speeds_rpm.clear();
      plan.loads_Nm.clear();
      parse_operating_points(d["operating_points"], lim, plan.operating_points);
    }
  } else if ((has_speed || has_load) && !plan.operating_points.empty()) {
    d[has_speed ? "speed_rpm" : "load_Nm"].fail("the preset " + in_quotes(plan.preset) +
                                                " gives operating points; override them with " + d.pointer() +
                                                "/operating_points");
  } else {
    if (has_speed) {
      if (auto v = dimension(d["speed_rpm"], positive_at_most(lim.max_speed_rpm, "/limits/max_speed_rpm")))
        plan.speeds_rpm = *v;
    }
    if (has_load) {
      if (auto v = dimension(d["load_Nm"], non_negative_at_most(lim.max_load_Nm, "/limits/max_load_Nm")))
        plan.loads_Nm = *v;
    }
  }
  if (d.has("angle_deg")) {
    if (grid) {
      if (auto v = dimension(d["angle_deg"], angle_check())) plan.angles_deg = *v;
    } else {
      d["angle_deg"].fail("not used in adaptive mode: the search picks the angles within /adaptive/bracket_deg");
    }
  }
  if (d.has("configurations"))
    parse_configurations(d["configurations"], plan.preset == kThesisGridPreset, plan.configurations);
}

void parse_adaptive(const JsonNode& v, AngleSearchOptions& a) {
  if (!v.object()) return;
  v.reject_unknown({"bracket_deg", "tolerance_deg", "max_evaluations", "stencil_deg", "resolution_deg",
                    "angle_u_target_deg"});
  if (const JsonNode b = v["bracket_deg"]; b.present()) {
    if (!b.json().is_array() || b.json().size() != 2) {
      b.fail("must be [from, to]");
    } else {
      const auto from = b.at(0).number(angle_check());
      const auto to = b.at(1).number(angle_check());
      if (from && to) {
        if (*from >= *to) {
          b.at(1).fail("must be above the bracket's start (" + num(*from) + ")");
        } else {
          a.from_deg = *from;
          a.to_deg = *to;
        }
      }
    }
  }
  set(v["tolerance_deg"], a.tolerance_deg, above_at_most(0, 10, "deg"));
  set(v["stencil_deg"], a.stencil_deg, above_at_most(0, 45, "deg"));
  set(v["resolution_deg"], a.resolution_deg, above_at_most(0, 1, "deg"));
  set_or_clear(v["angle_u_target_deg"], a.angle_u_target_deg, above_at_most(0, 45, "deg"));
  // Golden section needs two points and a parabola three.
  if (auto m = v["max_evaluations"].integer(3, 100)) a.max_evaluations = static_cast<std::size_t>(*m);
}

// "precision": {"pdcm_u_repeat_target_W": 0.05, "max_window_s": 8, "mode": "lengthen"}; null
// (or absent) measures every point once.
void parse_precision(const JsonNode& v, const SweepPlan& plan, std::optional<PrecisionOptions>& out) {
  if (!v.present()) return;
  if (v.is_null()) {
    out.reset();
    return;
  }
  if (!v.object()) return;
  v.reject_unknown({"pdcm_u_repeat_target_W", "max_window_s", "mode"});
  PrecisionOptions p = out.value_or(PrecisionOptions{});
  if (!v.has("pdcm_u_repeat_target_W") && !out)
    v["pdcm_u_repeat_target_W"].fail("required field is missing");
  set(v["pdcm_u_repeat_target_W"], p.pdcm_u_repeat_target_W, above_at_most(0, 1000, "W"));
  set(v["max_window_s"], p.max_window_s, within(kMinWindow_s, 3600, "s"));
  if (auto m = v["mode"].choice<PrecisionMode>(kPrecisionModeNames, "precision mode")) p.mode = *m;
  if (p.max_window_s < plan.window_s)
    v["max_window_s"].fail("must be at least the plan's window_s (" + num(plan.window_s) + " s)");
  out = p;
}

void parse_gate(const JsonNode& v, GateOptions& g) {
  if (!v.object()) return;
  v.reject_unknown({"span_s", "speed_band_rpm", "im_band_rel", "im_band_min_A", "power_band_rel", "power_band_min_W",
                    "average_s", "min_settle_s", "timeout_s"});
  // The band floors must be > 0: a zero band is never met by a measured signal.
  set(v["span_s"], g.bands.span_s, positive());
  set(v["speed_band_rpm"], g.bands.speed_band_rpm, positive());
  set(v["im_band_rel"], g.bands.im_band_rel, non_negative());
  set(v["im_band_min_A"], g.bands.im_band_min_A, positive());
  set(v["power_band_rel"], g.bands.power_band_rel, non_negative());
  set(v["power_band_min_W"], g.bands.power_band_min_W, positive());
  set(v["average_s"], g.bands.average_s, non_negative());
  set(v["min_settle_s"], g.min_settle_s, non_negative());
  set(v["timeout_s"], g.timeout_s, positive());
  if (g.timeout_s <= g.min_settle_s)
    v["timeout_s"].fail(num(g.timeout_s) + " must exceed min_settle_s (" + num(g.min_settle_s) + ")");
}

void parse_thermal(const JsonNode& v, ThermalOptions& t, const SweepLimits& lim) {
  if (v.present()) {
    if (!v.object()) return;
    v.reject_unknown({"enabled", "target_C", "band_C", "warmup_load_Nm", "warmup_speed_rpm", "timeout_s"});
    if (auto e = v["enabled"].boolean()) t.enabled = *e;
    set(v["target_C"], t.target_C, within(0, 200, "degC"));
    set(v["band_C"], t.band_C, positive());
    set(v["warmup_load_Nm"], t.warmup_load_Nm, non_negative());
    set_or_clear(v["warmup_speed_rpm"], t.warmup_speed_rpm, positive());
    set(v["timeout_s"], t.timeout_s, positive());
  }
  // Checked against the limits also when the values are defaults, so lowering a limit cannot
  // leave a default beyond it.
  if (t.target_C + t.band_C >= lim.max_temp_C)
    v["target_C"].fail("target_C + band_C (" + num(t.target_C + t.band_C) + ") must stay below /limits/max_temp_C (" +
                       num(lim.max_temp_C) + ")");
  if (t.warmup_load_Nm > lim.max_load_Nm)
    v["warmup_load_Nm"].fail(num(t.warmup_load_Nm) + " exceeds /limits/max_load_Nm (" + num(lim.max_load_Nm) + ")");
  if (t.warmup_speed_rpm && *t.warmup_speed_rpm > lim.max_speed_rpm)
    v["warmup_speed_rpm"].fail(num(*t.warmup_speed_rpm) + " exceeds /limits/max_speed_rpm (" +
                               num(lim.max_speed_rpm) + ")");
}

bool speed_allowed(const PlannedConfiguration& c, double speed_rpm) {
  return speed_rpm >= c.min_speed_rpm && (!c.max_speed_rpm || speed_rpm <= *c.max_speed_rpm);
}

// A configuration whose speed range misses every speed of the plan would silently measure
// nothing; so would an empty plan.
void check_coverage(JsonReader& p, const json& doc, const SweepPlan& plan) {
  // Values from the document were checked against the limits as they were read; a preset's
  // values are checked here, and reported at /preset.
  const json* dims = doc.contains("dimensions") && doc["dimensions"].is_object() ? &doc["dimensions"] : nullptr;
  auto from_doc = [&](const char* key) { return dims && dims->contains(key); };
  const auto& lim = plan.limits;
  if (!from_doc("speed_rpm") && !from_doc("operating_points")) {
    for (double s : plan.speeds_rpm)
      if (s > lim.max_speed_rpm)
        p.fail("/preset", "the preset's speed " + num(s) + " rpm exceeds /limits/max_speed_rpm (" +
                              num(lim.max_speed_rpm) + ")");
    for (const auto& op : plan.operating_points)
      if (op.speed_rpm > lim.max_speed_rpm)
        p.fail("/preset", "the preset's speed " + num(op.speed_rpm) + " rpm exceeds /limits/max_speed_rpm (" +
                              num(lim.max_speed_rpm) + ")");
  }
  if (!from_doc("load_Nm") && !from_doc("operating_points")) {
    for (double l : plan.loads_Nm)
      if (l > lim.max_load_Nm)
        p.fail("/preset", "the preset's load " + num(l) + " N m exceeds /limits/max_load_Nm (" +
                              num(lim.max_load_Nm) + ")");
    for (const auto& op : plan.operating_points)
      if (op.load_Nm > lim.max_load_Nm)
        p.fail("/preset", "the preset's load " + num(op.load_Nm) + " N m exceeds /limits/max_load_Nm (" +
                              num(lim.max_load_Nm) + ")");
  }
  if (!p.errors.empty()) return;

  // A gate that needs its timeout's worth of samples can never pass: every point unstable.
  const auto& gate = plan.gate;
  if (gate.bands.average_s + gate.bands.span_s >= gate.timeout_s)
    p.fail("/gate/average_s", num(gate.bands.average_s) + " + span_s (" + num(gate.bands.span_s) +
                                  ") must stay below timeout_s (" + num(gate.timeout_s) + ")");
  const bool listed = from_doc("configurations");
  for (std::size_t i = 0; i < plan.configurations.size(); ++i) {
    const auto& c = plan.configurations[i];
    if (!c.gate_average_s || *c.gate_average_s + gate.bands.span_s < gate.timeout_s) continue;
    // A preset's own configurations: the plan's timeout is what the document gave.
    if (listed)
      p.fail("/dimensions/configurations/" + std::to_string(i) + "/gate_average_s",
             num(*c.gate_average_s) + " + /gate/span_s (" + num(gate.bands.span_s) +
                 ") must stay below /gate/timeout_s (" + num(gate.timeout_s) + ")");
    else
      p.fail("/gate/timeout_s", num(gate.timeout_s) + " leaves " + label(c.configuration) +
                                    " no time: its gate averages over " + num(*c.gate_average_s) + " s");
  }
  if (!p.errors.empty()) return;

  std::vector<double> speeds = plan.speeds_rpm;
  for (const auto& op : plan.operating_points) speeds.push_back(op.speed_rpm);
  std::size_t pairs_total = 0;
  for (std::size_t i = 0; i < plan.configurations.size(); ++i) {
    const auto& c = plan.configurations[i];
    std::size_t n = 0;
    for (double s : speeds) n += speed_allowed(c, s) ? 1 : 0;
    if (n == 0 && !speeds.empty()) {
      p.fail(listed ? "/dimensions/configurations/" + std::to_string(i) : "/dimensions",
             label(c.configuration) + " is restricted to speeds no point of the plan has");
    }
    pairs_total += n;
  }
  const std::size_t loads = plan.operating_points.empty() ? plan.loads_Nm.size() : 1;
  const std::size_t angles = plan.mode == SweepMode::grid ? plan.angles_deg.size() : 1;
  const double total = static_cast<double>(pairs_total) * static_cast<double>(loads) * static_cast<double>(angles);
  if (total > static_cast<double>(kMaxPoints))
    p.fail("/dimensions", "the plan has " + num(total) + " points; at most " + std::to_string(kMaxPoints));
}

}  // namespace

SweepPlanParseResult parse_sweep_plan(const synbench::Json& doc) {
  JsonReader r;
  const JsonNode root = drivers::read_root(doc, r);
  SweepPlanParseResult result;
  if (!root.object()) {
    result.errors = std::move(r.errors);
    return result;
  }
  root.reject_unknown({"name", "preset", "dimensions", "order", "mode", "adaptive", "gate", "window_s", "precision",
                       "thermal", "limits", "notes"});

  const bool has_preset = root.has("preset");
  SweepPlan plan = has_preset ? preset_plan(root["preset"]) : SweepPlan{};

  parse_limits(root["limits"], plan.limits);

  if (auto s = root["name"].text()) plan.name = *s;
  if (plan.name.empty()) plan.name = plan.preset.empty() ? "sweep" : plan.preset;

  if (auto m = root["mode"].choice<SweepMode>(kSweepModeNames, "mode")) plan.mode = *m;

  if (auto s = root["order"].text()) {
    std::array<SweepDimension, 4> order{};
    std::size_t n = 0;
    bool ok = true;
    std::set<SweepDimension> seen;
    std::stringstream in(*s);
    std::string part;
    while (std::getline(in, part, '-')) {
      const auto d = parse_dimension(part);
      if (!d || seen.count(*d) || n >= 4) {
        ok = false;
        break;
      }
      seen.insert(*d);
      order[n++] = *d;
    }
    if (!ok || n != 4) {
      root["order"].fail(in_quotes(*s) + " must name speed, load, config and angle once each, outermost first, "
                                         "joined by '-' (e.g. speed-load-config-angle)");
    } else {
      plan.order = order;
    }
  }
  if (plan.mode == SweepMode::adaptive && plan.order[3] != SweepDimension::angle)
    root[root.has("order") ? "order" : "mode"].fail(
        "adaptive mode searches the angle innermost: the order must end with 'angle'");

  parse_dimensions(root["dimensions"], plan, has_preset);
  parse_adaptive(root["adaptive"], plan.adaptive);
  parse_gate(root["gate"], plan.gate);
  set(root["window_s"], plan.window_s, within(kMinWindow_s, 3600, "s"));
  parse_precision(root["precision"], plan, plan.precision);
  parse_thermal(root["thermal"], plan.thermal, plan.limits);
  if (auto notes = root["notes"].texts()) plan.notes = *notes;

  // Required dimensions that neither the document nor a preset supplied.
  if (const JsonNode d = root["dimensions"]; d.present() && d.json().is_object()) {
    if (plan.operating_points.empty() && !d.has("operating_points")) {
      if (plan.speeds_rpm.empty() && !d.has("speed_rpm"))
        d["speed_rpm"].fail("required field is missing (or give operating_points, or a preset)");
      if (plan.loads_Nm.empty() && !d.has("load_Nm"))
        d["load_Nm"].fail("required field is missing (or give operating_points, or a preset)");
    }
    if (plan.mode == SweepMode::grid && plan.angles_deg.empty() && !d.has("angle_deg"))
      d["angle_deg"].fail("required field in grid mode is missing");
  }
  if (plan.configurations.empty()) plan.configurations = {PlannedConfiguration{}};

  if (r.ok()) check_coverage(r, doc, plan);
  if (r.ok()) result.plan = std::move(plan);
  result.errors = std::move(r.errors);
  return result;
}

}  // namespace synbench::bench
