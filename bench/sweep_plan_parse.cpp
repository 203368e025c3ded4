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

#include "bench/sweep_plan.hpp"
#include "bench/sweep_presets.hpp"

namespace synbench::bench {
namespace {

using json = synbench::Json;

constexpr std::size_t kMaxDimensionValues = 10000;  // a range with more is a typo, not a plan
constexpr std::size_t kMaxPoints = 1000000;

// JSON keys starting with '_' are comments, as in config/twin.json and the device profiles.
bool is_comment(const std::string& key) { return !key.empty() && key.front() == '_'; }

std::string token(std::string_view key) {
  std::string out;
  for (char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string in_quotes(std::string_view s) { return "'" + std::string(s) + "'"; }

// A value check: empty string when fine, else the reason.
using Check = std::function<std::string(double)>;

Check positive() {
  return [](double v) { return v > 0 ? std::string() : "must be > 0"; };
}
Check non_negative() {
  return [](double v) { return v >= 0 ? std::string() : "must be >= 0"; };
}
Check within(double lo, double hi, const char* unit) {
  return [=](double v) {
    return v >= lo && v <= hi ? std::string() : "must be within [" + num(lo) + ", " + num(hi) + "] " + unit;
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
    return v > 0 && v < 90 ? std::string() : "must be inside (0, 90) deg (the motoring region)";
  };
}

class Parser {
 public:
  std::vector<SweepPlanError> errors;

  void fail(std::string ptr, std::string reason) { errors.push_back({std::move(ptr), std::move(reason)}); }

  bool object(const json& v, const std::string& ptr) {
    if (v.is_object()) return true;
    fail(ptr, "must be a JSON object");
    return false;
  }

  void reject_unknown(const json& obj, const std::string& ptr, std::initializer_list<std::string_view> known) {
    for (const auto& [key, value] : obj.items()) {
      if (is_comment(key)) continue;
      if (std::find(known.begin(), known.end(), key) == known.end()) fail(ptr + "/" + token(key), "unknown field");
    }
  }

  // A number at obj[key]: nothing when absent or invalid (invalid is reported).
  std::optional<double> number(const json& obj, const std::string& ptr, const char* key, const Check& check) {
    const auto it = obj.find(key);
    if (it == obj.end()) return std::nullopt;
    return number_value(*it, ptr + "/" + key, check);
  }

  std::optional<double> number_value(const json& v, const std::string& ptr, const Check& check) {
    if (!v.is_number() || !std::isfinite(v.get<double>())) {
      fail(ptr, "must be a finite number");
      return std::nullopt;
    }
    const double x = v.get<double>();
    if (check) {
      if (auto reason = check(x); !reason.empty()) {
        fail(ptr, reason);
        return std::nullopt;
      }
    }
    return x;
  }

  // Overwrites `out` when obj[key] is present and valid.
  void set(const json& obj, const std::string& ptr, const char* key, double& out, const Check& check) {
    if (auto v = number(obj, ptr, key, check)) out = *v;
  }

  void set_bool(const json& obj, const std::string& ptr, const char* key, bool& out) {
    const auto it = obj.find(key);
    if (it == obj.end()) return;
    if (!it->is_boolean()) {
      fail(ptr + "/" + key, "must be true or false");
      return;
    }
    out = it->get<bool>();
  }

  // A dimension: a non-empty list of numbers or a range {from, to, step}. Every value is checked;
  // duplicates are rejected (they would measure a point twice under two indices).
  std::optional<std::vector<double>> dimension(const json& v, const std::string& ptr, const Check& check) {
    if (v.is_array()) return list(v, ptr, check);
    if (v.is_object()) return range(v, ptr, check);
    fail(ptr, "must be a list of numbers or a range {\"from\", \"to\", \"step\"}");
    return std::nullopt;
  }

  std::optional<std::vector<double>> list(const json& v, const std::string& ptr, const Check& check) {
    if (v.empty()) {
      fail(ptr, "must not be empty");
      return std::nullopt;
    }
    if (v.size() > kMaxDimensionValues) {
      fail(ptr, "has " + std::to_string(v.size()) + " values; at most " + std::to_string(kMaxDimensionValues));
      return std::nullopt;
    }
    std::vector<double> out;
    bool ok = true;
    for (std::size_t i = 0; i < v.size(); ++i) {
      const std::string p = ptr + "/" + std::to_string(i);
      const auto x = number_value(v[i], p, check);
      if (!x) {
        ok = false;
        continue;
      }
      for (std::size_t j = 0; j < out.size(); ++j) {
        if (std::fabs(out[j] - *x) <= 1e-9 * std::max(1.0, std::fabs(*x))) {
          fail(p, "duplicate of " + ptr + "/" + std::to_string(j) + " (" + num(*x) + ")");
          ok = false;
        }
      }
      out.push_back(*x);
    }
    if (!ok) return std::nullopt;
    return out;
  }

  std::optional<std::vector<double>> range(const json& v, const std::string& ptr, const Check& check) {
    reject_unknown(v, ptr, {"from", "to", "step"});
    const std::size_t before = errors.size();
    for (const char* key : {"from", "to", "step"})
      if (!v.contains(key)) fail(ptr + "/" + key, "required field is missing");
    const auto from = number(v, ptr, "from", check);
    const auto to = number(v, ptr, "to", check);
    const auto step = number(v, ptr, "step", positive());
    if (errors.size() != before || !from || !to || !step) return std::nullopt;
    if (*from > *to) {
      fail(ptr + "/to", "must be >= from (" + num(*from) + ")");
      return std::nullopt;
    }
    const double steps = (*to - *from) / *step;
    if (steps + 1 > static_cast<double>(kMaxDimensionValues)) {
      fail(ptr + "/step", "gives " + num(std::floor(steps) + 1) + " values; at most " +
                              std::to_string(kMaxDimensionValues));
      return std::nullopt;
    }
    if (std::fabs(steps - std::round(steps)) > 1e-6) {
      const auto values = inclusive_range(*from, *to, *step);
      fail(ptr + "/to", num(*to) + " is not reached from " + num(*from) + " in whole steps of " + num(*step) +
                            " (the last value would be " + num(values.back()) + ")");
      return std::nullopt;
    }
    return inclusive_range(*from, *to, *step);
  }

  std::optional<std::string> string(const json& obj, const std::string& ptr, const char* key) {
    const auto it = obj.find(key);
    if (it == obj.end()) return std::nullopt;
    if (!it->is_string()) {
      fail(ptr + "/" + key, "must be a string");
      return std::nullopt;
    }
    return it->get<std::string>();
  }
};

std::string estimator_list() {
  std::string s;
  for (auto n : drivers::kEstimatorNames) s += (s.empty() ? "" : ", ") + std::string(n);
  return s;
}

std::string pwm_list() {
  std::string s;
  for (auto n : drivers::kPwmNames) s += (s.empty() ? "" : ", ") + std::string(n);
  return s;
}

std::optional<SweepDimension> parse_dimension(std::string_view s) {
  for (auto d : {SweepDimension::speed, SweepDimension::load, SweepDimension::config, SweepDimension::angle})
    if (name(d) == s) return d;
  return std::nullopt;
}

// "preset": "thesis-grid" or {"name": "iec-61800-9-2", "rated_speed_rpm": ..., ...}
SweepPlan preset_plan(Parser& p, const json& v) {
  const std::string ptr = "/preset";
  std::string preset;
  const json* options = nullptr;
  if (v.is_string()) {
    preset = v.get<std::string>();
  } else if (v.is_object()) {
    options = &v;
    if (auto s = p.string(v, ptr, "name")) preset = *s;
    else if (!v.contains("name")) p.fail(ptr + "/name", "required field is missing");
  } else {
    p.fail(ptr, "must be a preset name or an object {\"name\": ...}");
    return SweepPlan{};
  }
  const std::string name_ptr = options ? ptr + "/name" : ptr;
  if (preset == kThesisGridPreset) {
    if (options) p.reject_unknown(*options, ptr, {"name"});
    return thesis_grid_plan();
  }
  if (preset == kIecPreset) {
    IecPresetOptions o;
    if (options) {
      p.reject_unknown(*options, ptr, {"name", "rated_speed_rpm", "rated_torque_Nm", "zero_speed_rpm"});
      p.set(*options, ptr, "rated_speed_rpm", o.rated_speed_rpm, positive());
      p.set(*options, ptr, "rated_torque_Nm", o.rated_torque_Nm, positive());
      p.set(*options, ptr, "zero_speed_rpm", o.zero_speed_rpm, non_negative());
    }
    return iec_61800_9_2_plan(o);
  }
  if (!preset.empty() || v.is_string()) {
    std::string known;
    for (auto n : kPresetNames) known += (known.empty() ? "" : ", ") + std::string(n);
    p.fail(name_ptr, "unknown preset " + in_quotes(preset) + " (expected " + known + ")");
  }
  return SweepPlan{};
}

void parse_limits(Parser& p, const json& doc, SweepLimits& l) {
  const auto it = doc.find("limits");
  if (it == doc.end()) return;
  const std::string ptr = "/limits";
  if (!p.object(*it, ptr)) return;
  const json& v = *it;
  p.reject_unknown(v, ptr, {"max_speed_rpm", "max_load_Nm", "max_current_A", "max_udc_V", "min_udc_V", "max_temp_C"});
  p.set(v, ptr, "max_speed_rpm", l.max_speed_rpm, positive());
  p.set(v, ptr, "max_load_Nm", l.max_load_Nm, positive());
  p.set(v, ptr, "max_current_A", l.max_current_A, positive());
  p.set(v, ptr, "max_udc_V", l.max_udc_V, positive());
  p.set(v, ptr, "min_udc_V", l.min_udc_V, non_negative());
  p.set(v, ptr, "max_temp_C", l.max_temp_C, within(-40, 250, "degC"));
  if (l.min_udc_V >= l.max_udc_V)
    p.fail(ptr + "/min_udc_V", num(l.min_udc_V) + " must be below max_udc_V (" + num(l.max_udc_V) + ")");
}

void parse_configurations(Parser& p, const json& v, const std::string& ptr, bool thesis_rules,
                          std::vector<PlannedConfiguration>& out) {
  if (!v.is_array()) {
    p.fail(ptr, "must be a list of {\"estimator\", \"pwm\"}");
    return;
  }
  if (v.empty()) {
    p.fail(ptr, "must not be empty");
    return;
  }
  std::vector<PlannedConfiguration> list;
  bool ok = true;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string cp = ptr + "/" + std::to_string(i);
    if (!p.object(v[i], cp)) {
      ok = false;
      continue;
    }
    const json& c = v[i];
    const std::size_t before = p.errors.size();
    p.reject_unknown(c, cp, {"estimator", "pwm", "min_speed_rpm", "max_speed_rpm", "gate_average_s"});
    PlannedConfiguration pc;
    const auto est = p.string(c, cp, "estimator");
    const auto pwm = p.string(c, cp, "pwm");
    if (!c.contains("estimator")) p.fail(cp + "/estimator", "required field is missing");
    if (!c.contains("pwm")) p.fail(cp + "/pwm", "required field is missing");
    if (est) {
      if (auto e = drivers::parse_estimator(*est)) pc.configuration.estimator = *e;
      else p.fail(cp + "/estimator", "unknown estimator " + in_quotes(*est) + " (expected " + estimator_list() + ")");
    }
    if (pwm) {
      if (auto w = drivers::parse_pwm(*pwm)) pc.configuration.pwm = *w;
      else p.fail(cp + "/pwm", "unknown PWM scheme " + in_quotes(*pwm) + " (expected " + pwm_list() + ")");
    }
    if (thesis_rules) pc = with_thesis_defaults(pc.configuration);
    p.set(c, cp, "min_speed_rpm", pc.min_speed_rpm, non_negative());
    if (const auto it = c.find("max_speed_rpm"); it != c.end() && !it->is_null()) {
      if (auto x = p.number_value(*it, cp + "/max_speed_rpm", positive())) pc.max_speed_rpm = *x;
    }
    if (const auto it = c.find("gate_average_s"); it != c.end()) {
      if (it->is_null()) pc.gate_average_s.reset();
      else if (auto x = p.number_value(*it, cp + "/gate_average_s", non_negative())) pc.gate_average_s = *x;
    }
    if (pc.max_speed_rpm && *pc.max_speed_rpm < pc.min_speed_rpm)
      p.fail(cp + "/max_speed_rpm", "must be >= min_speed_rpm (" + num(pc.min_speed_rpm) + ")");
    if (p.errors.size() != before) {
      ok = false;
      continue;
    }
    for (std::size_t j = 0; j < list.size(); ++j) {
      if (list[j].configuration == pc.configuration) {
        p.fail(cp, "duplicate of " + ptr + "/" + std::to_string(j) + " (" + label(pc.configuration) + ")");
        ok = false;
      }
    }
    list.push_back(pc);
  }
  if (ok) out = std::move(list);
}

void parse_operating_points(Parser& p, const json& v, const std::string& ptr, const SweepLimits& lim,
                            std::vector<OperatingPoint>& out) {
  if (!v.is_array()) {
    p.fail(ptr, "must be a list of {\"speed_rpm\", \"load_Nm\"}");
    return;
  }
  if (v.empty()) {
    p.fail(ptr, "must not be empty");
    return;
  }
  std::vector<OperatingPoint> list;
  bool ok = true;
  for (std::size_t i = 0; i < v.size(); ++i) {
    const std::string op = ptr + "/" + std::to_string(i);
    if (!p.object(v[i], op)) {
      ok = false;
      continue;
    }
    const json& o = v[i];
    const std::size_t before = p.errors.size();
    p.reject_unknown(o, op, {"speed_rpm", "load_Nm", "label"});
    for (const char* key : {"speed_rpm", "load_Nm"})
      if (!o.contains(key)) p.fail(op + "/" + key, "required field is missing");
    OperatingPoint pt;
    p.set(o, op, "speed_rpm", pt.speed_rpm, positive_at_most(lim.max_speed_rpm, "/limits/max_speed_rpm"));
    p.set(o, op, "load_Nm", pt.load_Nm, non_negative_at_most(lim.max_load_Nm, "/limits/max_load_Nm"));
    if (auto s = p.string(o, op, "label")) pt.label = *s;
    if (p.errors.size() != before) {
      ok = false;
      continue;
    }
    for (std::size_t j = 0; j < list.size(); ++j) {
      if (list[j].speed_rpm == pt.speed_rpm && list[j].load_Nm == pt.load_Nm) {
        p.fail(op, "duplicate of " + ptr + "/" + std::to_string(j));
        ok = false;
      }
    }
    list.push_back(pt);
  }
  if (ok) out = std::move(list);
}

void parse_dimensions(Parser& p, const json& doc, SweepPlan& plan, bool has_preset) {
  const auto it = doc.find("dimensions");
  const bool grid = plan.mode == SweepMode::grid;
  if (plan.mode == SweepMode::adaptive) plan.angles_deg.clear();
  if (it == doc.end()) {
    if (!has_preset) p.fail("/dimensions", "required field is missing (or name a preset)");
    return;
  }
  const std::string ptr = "/dimensions";
  if (!p.object(*it, ptr)) return;
  const json& d = *it;
  p.reject_unknown(d, ptr, {"speed_rpm", "load_Nm", "angle_deg", "operating_points", "configurations"});
  const auto& lim = plan.limits;

  const bool has_speed = d.contains("speed_rpm"), has_load = d.contains("load_Nm");
  const bool has_points = d.contains("operating_points");
  if (has_points) {
    if (has_speed || has_load) {
      p.fail(ptr + "/operating_points", "cannot be combined with speed_rpm and load_Nm (it replaces both)");
    } else {
      plan.speeds_rpm.clear();
      plan.loads_Nm.clear();
      parse_operating_points(p, d["operating_points"], ptr + "/operating_points", lim, plan.operating_points);
    }
  } else if ((has_speed || has_load) && !plan.operating_points.empty()) {
    p.fail(ptr + (has_speed ? "/speed_rpm" : "/load_Nm"),
           "the preset " + in_quotes(plan.preset) + " gives operating points; override them with " + ptr +
               "/operating_points");
  } else {
    if (has_speed) {
      if (auto v = p.dimension(d["speed_rpm"], ptr + "/speed_rpm",
                               positive_at_most(lim.max_speed_rpm, "/limits/max_speed_rpm")))
        plan.speeds_rpm = *v;
    }
    if (has_load) {
      if (auto v = p.dimension(d["load_Nm"], ptr + "/load_Nm",
                               non_negative_at_most(lim.max_load_Nm, "/limits/max_load_Nm")))
        plan.loads_Nm = *v;
    }
  }
  if (d.contains("angle_deg")) {
    if (grid) {
      if (auto v = p.dimension(d["angle_deg"], ptr + "/angle_deg", angle_check())) plan.angles_deg = *v;
    } else {
      p.fail(ptr + "/angle_deg", "not used in adaptive mode: the search picks the angles within /adaptive/bracket_deg");
    }
  }
  if (d.contains("configurations"))
    parse_configurations(p, d["configurations"], ptr + "/configurations", plan.preset == kThesisGridPreset,
                         plan.configurations);
}

void parse_adaptive(Parser& p, const json& doc, AngleSearchOptions& a) {
  const auto it = doc.find("adaptive");
  if (it == doc.end()) return;
  const std::string ptr = "/adaptive";
  if (!p.object(*it, ptr)) return;
  const json& v = *it;
  p.reject_unknown(v, ptr, {"bracket_deg", "tolerance_deg", "max_evaluations", "stencil_deg", "resolution_deg"});
  if (const auto b = v.find("bracket_deg"); b != v.end()) {
    if (!b->is_array() || b->size() != 2) {
      p.fail(ptr + "/bracket_deg", "must be [from, to]");
    } else {
      const auto from = p.number_value((*b)[0], ptr + "/bracket_deg/0", angle_check());
      const auto to = p.number_value((*b)[1], ptr + "/bracket_deg/1", angle_check());
      if (from && to) {
        if (*from >= *to) {
          p.fail(ptr + "/bracket_deg/1", "must be above the bracket's start (" + num(*from) + ")");
        } else {
          a.from_deg = *from;
          a.to_deg = *to;
        }
      }
    }
  }
  p.set(v, ptr, "tolerance_deg", a.tolerance_deg, [](double x) {
    return x > 0 && x <= 10 ? std::string() : "must be within (0, 10] deg";
  });
  p.set(v, ptr, "stencil_deg", a.stencil_deg, [](double x) {
    return x > 0 && x <= 45 ? std::string() : "must be within (0, 45] deg";
  });
  p.set(v, ptr, "resolution_deg", a.resolution_deg, [](double x) {
    return x > 0 && x <= 1 ? std::string() : "must be within (0, 1] deg";
  });
  if (const auto m = v.find("max_evaluations"); m != v.end()) {
    // Golden section needs two points and a parabola three.
    if (!m->is_number_integer() || m->get<std::int64_t>() < 3 || m->get<std::int64_t>() > 100)
      p.fail(ptr + "/max_evaluations", "must be an integer in 3..100");
    else
      a.max_evaluations = static_cast<std::size_t>(m->get<std::int64_t>());
  }
}

void parse_gate(Parser& p, const json& doc, GateOptions& g) {
  const auto it = doc.find("gate");
  if (it == doc.end()) return;
  const std::string ptr = "/gate";
  if (!p.object(*it, ptr)) return;
  const json& v = *it;
  p.reject_unknown(v, ptr, {"span_s", "speed_band_rpm", "im_band_rel", "im_band_min_A", "power_band_rel",
                            "power_band_min_W", "average_s", "min_settle_s", "timeout_s"});
  // The band floors must be > 0: a zero band is never met by a measured signal.
  p.set(v, ptr, "span_s", g.bands.span_s, positive());
  p.set(v, ptr, "speed_band_rpm", g.bands.speed_band_rpm, positive());
  p.set(v, ptr, "im_band_rel", g.bands.im_band_rel, non_negative());
  p.set(v, ptr, "im_band_min_A", g.bands.im_band_min_A, positive());
  p.set(v, ptr, "power_band_rel", g.bands.power_band_rel, non_negative());
  p.set(v, ptr, "power_band_min_W", g.bands.power_band_min_W, positive());
  p.set(v, ptr, "average_s", g.bands.average_s, non_negative());
  p.set(v, ptr, "min_settle_s", g.min_settle_s, non_negative());
  p.set(v, ptr, "timeout_s", g.timeout_s, positive());
  if (g.timeout_s <= g.min_settle_s)
    p.fail(ptr + "/timeout_s", num(g.timeout_s) + " must exceed min_settle_s (" + num(g.min_settle_s) + ")");
}

void parse_thermal(Parser& p, const json& doc, ThermalOptions& t, const SweepLimits& lim) {
  const std::string ptr = "/thermal";
  const auto it = doc.find("thermal");
  if (it != doc.end()) {
    if (!p.object(*it, ptr)) return;
    const json& v = *it;
    p.reject_unknown(v, ptr, {"enabled", "target_C", "band_C", "warmup_load_Nm", "warmup_speed_rpm", "timeout_s"});
    p.set_bool(v, ptr, "enabled", t.enabled);
    p.set(v, ptr, "target_C", t.target_C, within(0, 200, "degC"));
    p.set(v, ptr, "band_C", t.band_C, positive());
    p.set(v, ptr, "warmup_load_Nm", t.warmup_load_Nm, non_negative());
    if (const auto w = v.find("warmup_speed_rpm"); w != v.end()) {
      if (w->is_null()) t.warmup_speed_rpm.reset();
      else if (auto x = p.number_value(*w, ptr + "/warmup_speed_rpm", positive())) t.warmup_speed_rpm = *x;
    }
    p.set(v, ptr, "timeout_s", t.timeout_s, positive());
  }
  // Checked against the limits also when the values are defaults, so lowering a limit cannot
  // leave a default beyond it.
  if (t.target_C + t.band_C >= lim.max_temp_C)
    p.fail(ptr + "/target_C", "target_C + band_C (" + num(t.target_C + t.band_C) +
                                  ") must stay below /limits/max_temp_C (" + num(lim.max_temp_C) + ")");
  if (t.warmup_load_Nm > lim.max_load_Nm)
    p.fail(ptr + "/warmup_load_Nm", num(t.warmup_load_Nm) + " exceeds /limits/max_load_Nm (" +
                                        num(lim.max_load_Nm) + ")");
  if (t.warmup_speed_rpm && *t.warmup_speed_rpm > lim.max_speed_rpm)
    p.fail(ptr + "/warmup_speed_rpm", num(*t.warmup_speed_rpm) + " exceeds /limits/max_speed_rpm (" +
                                          num(lim.max_speed_rpm) + ")");
}

bool speed_allowed(const PlannedConfiguration& c, double speed_rpm) {
  return speed_rpm >= c.min_speed_rpm && (!c.max_speed_rpm || speed_rpm <= *c.max_speed_rpm);
}

// A configuration whose speed range misses every speed of the plan would silently measure
// nothing; so would an empty plan.
void check_coverage(Parser& p, const json& doc, const SweepPlan& plan) {
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

std::string to_string(const SweepPlanError& e) {
  return (e.json_pointer.empty() ? std::string("(document)") : e.json_pointer) + ": " + e.reason;
}

SweepPlanParseResult parse_sweep_plan(const synbench::Json& doc) {
  Parser p;
  SweepPlanParseResult result;
  if (!doc.is_object()) {
    result.errors.push_back({"", "must be a JSON object"});
    return result;
  }
  p.reject_unknown(doc, "",
                   {"name", "preset", "dimensions", "order", "mode", "adaptive", "gate", "window_s", "thermal",
                    "limits", "notes"});

  const bool has_preset = doc.contains("preset");
  SweepPlan plan = has_preset ? preset_plan(p, doc["preset"]) : SweepPlan{};

  parse_limits(p, doc, plan.limits);

  if (auto s = p.string(doc, "", "name")) plan.name = *s;
  if (plan.name.empty()) plan.name = plan.preset.empty() ? "sweep" : plan.preset;

  if (auto s = p.string(doc, "", "mode")) {
    if (*s == "grid") plan.mode = SweepMode::grid;
    else if (*s == "adaptive") plan.mode = SweepMode::adaptive;
    else p.fail("/mode", "unknown mode " + in_quotes(*s) + " (expected grid, adaptive)");
  }

  if (auto s = p.string(doc, "", "order")) {
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
      p.fail("/order", in_quotes(*s) + " must name speed, load, config and angle once each, outermost first, "
                                    "joined by '-' (e.g. speed-load-config-angle)");
    } else {
      plan.order = order;
    }
  }
  if (plan.mode == SweepMode::adaptive && plan.order[3] != SweepDimension::angle)
    p.fail(doc.contains("order") ? "/order" : "/mode",
           "adaptive mode searches the angle innermost: the order must end with 'angle'");

  parse_dimensions(p, doc, plan, has_preset);
  parse_adaptive(p, doc, plan.adaptive);
  parse_gate(p, doc, plan.gate);
  if (doc.contains("window_s")) {
    p.set(doc, "", "window_s", plan.window_s, [](double x) {
      return x > 0 && x <= 3600 ? std::string() : "must be within (0, 3600] s";
    });
  }
  parse_thermal(p, doc, plan.thermal, plan.limits);

  if (const auto it = doc.find("notes"); it != doc.end()) {
    bool ok = it->is_array();
    if (ok)
      for (const auto& n : *it) ok = ok && n.is_string();
    if (!ok) p.fail("/notes", "must be a list of strings");
    else plan.notes = it->get<std::vector<std::string>>();
  }

  // Required dimensions that neither the document nor a preset supplied.
  if (doc.contains("dimensions") && doc["dimensions"].is_object()) {
    if (plan.operating_points.empty() && !doc["dimensions"].contains("operating_points")) {
      if (plan.speeds_rpm.empty() && !doc["dimensions"].contains("speed_rpm"))
        p.fail("/dimensions/speed_rpm", "required field is missing (or give operating_points, or a preset)");
      if (plan.loads_Nm.empty() && !doc["dimensions"].contains("load_Nm"))
        p.fail("/dimensions/load_Nm", "required field is missing (or give operating_points, or a preset)");
    }
    if (plan.mode == SweepMode::grid && plan.angles_deg.empty() && !doc["dimensions"].contains("angle_deg"))
      p.fail("/dimensions/angle_deg", "required field in grid mode is missing");
  }
  if (plan.configurations.empty()) plan.configurations = {PlannedConfiguration{}};

  if (p.errors.empty()) check_coverage(p, doc, plan);
  if (p.errors.empty()) result.plan = std::move(plan);
  result.errors = std::move(p.errors);
  return result;
}

}  // namespace synbench::bench
