// The merged study result; see study_analysis.hpp.
#include "bench/study_analysis.hpp"

#include "drivers/json.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <tuple>

#include "bench/analysis.hpp"

namespace synbench::bench {
namespace {

using json = synbench::Json;

// (configuration, speed, load): one curve of a sample.
using CurveKey = std::tuple<Configuration, double, double>;

struct Accumulator {
  std::size_t samples = 0, points = 0;
  double pos_sum = 0, pos_max = -1, speed_sum = 0, eff_sum = 0;
  std::size_t pos_n = 0, speed_n = 0, eff_n = 0;
  std::map<CurveKey, std::pair<double, std::size_t>> mtpa;  // sum of angles, curves
};

struct SampleSummary {
  std::map<Configuration, Accumulator> per_config;  // this sample alone
};

SampleSummary summarise(const std::vector<PointRecord>& records) {
  SampleSummary s;
  for (const auto& r : records) {
    auto& a = s.per_config[Configuration{r.estimator, r.pwm}];
    ++a.points;
    if (r.pos_err_mean_deg) {
      a.pos_sum += std::fabs(*r.pos_err_mean_deg);
      ++a.pos_n;
      a.pos_max = std::max({a.pos_max, std::fabs(*r.pos_err_mean_deg), std::fabs(r.pos_err_min_deg.value_or(0)),
                            std::fabs(r.pos_err_max_deg.value_or(0))});
    }
    if (r.speed_err_rpm) {
      a.speed_sum += std::fabs(*r.speed_err_rpm);
      ++a.speed_n;
    }
    if (std::isfinite(r.efficiency) && r.efficiency > 0) {
      a.eff_sum += r.efficiency;
      ++a.eff_n;
    }
  }
  AnalysisOptions o;
  o.uncertainty_draws = 0;  // the angles alone: the study's spread is over samples, not draws
  for (const auto& c : analyze(records, o).curves) {
    if (c.angles_deg.size() < 3) continue;
    auto& m = s.per_config[c.configuration].mtpa[{c.configuration, c.speed_rpm, c.load_Nm}];
    m.first += c.mtpa.angle_deg;
    ++m.second;
  }
  for (auto& [c, a] : s.per_config) a.samples = 1;
  return s;
}

void merge(Accumulator& into, const Accumulator& a) {
  into.samples += a.samples;
  into.points += a.points;
  into.pos_sum += a.pos_sum;
  into.pos_n += a.pos_n;
  into.pos_max = std::max(into.pos_max, a.pos_max);
  into.speed_sum += a.speed_sum;
  into.speed_n += a.speed_n;
  into.eff_sum += a.eff_sum;
  into.eff_n += a.eff_n;
  for (const auto& [k, v] : a.mtpa) {
    into.mtpa[k].first += v.first;
    into.mtpa[k].second += v.second;
  }
}

std::optional<double> mean(double sum, std::size_t n) {
  if (n == 0) return std::nullopt;
  return sum / static_cast<double>(n);
}

std::optional<double> mtpa_mean(const Accumulator& a) {
  double sum = 0;
  std::size_t n = 0;
  for (const auto& [k, v] : a.mtpa) {
    sum += v.first / static_cast<double>(v.second);
    ++n;
  }
  return mean(sum, n);
}

std::optional<double> mtpa_shift(const Accumulator& a, const Accumulator& nominal) {
  double sum = 0;
  std::size_t n = 0;
  for (const auto& [k, v] : a.mtpa) {
    const auto it = nominal.mtpa.find(k);
    if (it == nominal.mtpa.end()) continue;
    sum += v.first / static_cast<double>(v.second) - it->second.first / static_cast<double>(it->second.second);
    ++n;
  }
  return mean(sum, n);
}

void put(json& j, const char* key, const std::optional<double>& v) { j[key] = v ? json(*v) : json(); }

// A value with `decimals` decimals (and its sign when `sign`), "-" when there is none.
std::string cell(const std::optional<double>& v, int decimals, bool sign = false) {
  if (!v) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, sign ? "%+.*f" : "%.*f", decimals, *v);
  return buf;
}

}  // namespace

StudyAnalysis analyze_study(const StudyPlan& plan, const std::vector<StudySampleRecords>& samples, std::size_t bins) {
  StudyAnalysis out;
  out.samples_planned = sample_count(plan);
  std::vector<SampleSummary> summaries;
  for (const auto& s : samples) {
    summaries.push_back(summarise(s.records));
    out.points += s.records.size();
    if (!s.records.empty()) ++out.samples_with_points;
  }
  bins = std::max<std::size_t>(1, bins);
  std::vector<StudyParameter> varied;
  if (plan.kind == StudyKind::grid)
    for (const auto& [p, v] : plan.grid) varied.push_back(p);
  else
    for (const auto& d : plan.draws) varied.push_back(d.parameter);

  for (std::size_t k = 0; k < varied.size(); ++k) {
    StudyParameterResult pr;
    pr.parameter = varied[k];
    // The groups: grid values, or equal bins over the drawn range.
    if (plan.kind == StudyKind::grid) {
      auto values = plan.grid[k].second;
      std::sort(values.begin(), values.end());
      for (double v : values) pr.groups.push_back({v, v, v == 0, {}});
    } else {
      double lo = 0, hi = 0;
      bool any = false;
      for (const auto& s : samples) {
        const double v = s.sample.deviation[k].second;
        lo = any ? std::min(lo, v) : v;
        hi = any ? std::max(hi, v) : v;
        any = true;
      }
      if (!any) continue;
      if (hi <= lo) bins = 1;
      const double w = hi > lo ? (hi - lo) / static_cast<double>(bins) : 1.0;
      for (std::size_t b = 0; b < bins; ++b) {
        const double from = lo + w * static_cast<double>(b), to = b + 1 == bins ? hi : lo + w * static_cast<double>(b + 1);
        pr.groups.push_back({from, to, from <= 0 && (0 < to || (b + 1 == bins && 0 <= to)), {}});
      }
    }
    auto group_of = [&](double v) -> std::size_t {
      if (plan.kind == StudyKind::grid) {
        for (std::size_t g = 0; g < pr.groups.size(); ++g)
          if (pr.groups[g].from == v) return g;
        return 0;
      }
      const double lo = pr.groups.front().from, hi = pr.groups.back().to;
      if (hi <= lo) return 0;
      const auto g = static_cast<std::size_t>((v - lo) / (hi - lo) * static_cast<double>(pr.groups.size()));
      return std::min(g, pr.groups.size() - 1);
    };
    std::vector<std::map<Configuration, Accumulator>> acc(pr.groups.size());
    for (std::size_t i = 0; i < samples.size(); ++i)
      for (const auto& [c, a] : summaries[i].per_config) merge(acc[group_of(samples[i].sample.deviation[k].second)][c], a);
    const auto nominal = std::find_if(pr.groups.begin(), pr.groups.end(), [](const StudyGroup& g) { return g.nominal; });
    for (std::size_t g = 0; g < pr.groups.size(); ++g) {
      for (const auto& [c, a] : acc[g]) {
        StudyCell cellv;
        cellv.configuration = c;
        cellv.samples = a.samples;
        cellv.points = a.points;
        cellv.pos_err_abs_mean_deg = mean(a.pos_sum, a.pos_n);
        if (a.pos_n) cellv.pos_err_abs_max_deg = a.pos_max;
        cellv.speed_err_abs_mean_rpm = mean(a.speed_sum, a.speed_n);
        cellv.efficiency_mean = mean(a.eff_sum, a.eff_n);
        cellv.mtpa_angle_mean_deg = mtpa_mean(a);
        if (nominal != pr.groups.end()) {
          const auto& nom = acc[static_cast<std::size_t>(nominal - pr.groups.begin())];
          if (auto it = nom.find(c); it != nom.end()) cellv.mtpa_shift_deg = mtpa_shift(a, it->second);
        }
        pr.groups[g].cells.push_back(cellv);
      }
    }
    out.parameters.push_back(std::move(pr));
  }
  return out;
}

json to_json(const StudyAnalysis& a) {
  json j;
  j["samples_planned"] = a.samples_planned;
  j["samples_with_points"] = a.samples_with_points;
  j["points"] = a.points;
  json params = json::array();
  for (const auto& p : a.parameters) {
    json pj;
    pj["parameter"] = name(p.parameter);
    json groups = json::array();
    for (const auto& g : p.groups) {
      json gj;
      gj["from"] = g.from;
      gj["to"] = g.to;
      gj["nominal"] = g.nominal;
      json cells = json::array();
      for (const auto& c : g.cells) {
        json cj;
        cj["configuration"] = label(c.configuration);
        cj["samples"] = c.samples;
        cj["points"] = c.points;
        put(cj, "pos_err_abs_mean_deg", c.pos_err_abs_mean_deg);
        put(cj, "pos_err_abs_max_deg", c.pos_err_abs_max_deg);
        put(cj, "speed_err_abs_mean_rpm", c.speed_err_abs_mean_rpm);
        put(cj, "efficiency_mean", c.efficiency_mean);
        put(cj, "mtpa_angle_mean_deg", c.mtpa_angle_mean_deg);
        put(cj, "mtpa_shift_deg", c.mtpa_shift_deg);
        cells.push_back(cj);
      }
      gj["configurations"] = cells;
      groups.push_back(gj);
    }
    pj["groups"] = groups;
    params.push_back(pj);
  }
  j["parameters"] = params;
  return j;
}

std::string study_table(const StudyAnalysis& a) {
  std::string out = "samples " + std::to_string(a.samples_with_points) + " of " + std::to_string(a.samples_planned) +
                    " with points, " + std::to_string(a.points) + " points\n";
  char line[256];
  for (const auto& p : a.parameters) {
    std::snprintf(line, sizeof line, "\n%-22s %-18s %7s %7s %10s %10s %10s %8s %9s %9s\n",
                  std::string(name(p.parameter)).c_str(), "configuration", "samples", "points", "|pos| deg",
                  "max|pos|", "|spd| rpm", "eff", "MTPA deg", "shift deg");
    out += line;
    for (const auto& g : p.groups) {
      char range[48];
      if (g.from == g.to) std::snprintf(range, sizeof range, "%g%s", g.from, g.nominal ? " (nominal)" : "");
      else std::snprintf(range, sizeof range, "[%.3g, %.3g)%s", g.from, g.to, g.nominal ? " nom" : "");
      for (const auto& c : g.cells) {
        std::snprintf(line, sizeof line, "%-22s %-18s %7zu %7zu %10s %10s %10s %8s %9s %9s\n", range,
                      label(c.configuration).c_str(), c.samples, c.points, cell(c.pos_err_abs_mean_deg, 3).c_str(),
                      cell(c.pos_err_abs_max_deg, 2).c_str(), cell(c.speed_err_abs_mean_rpm, 2).c_str(),
                      cell(c.efficiency_mean, 4).c_str(), cell(c.mtpa_angle_mean_deg, 2).c_str(),
                      cell(c.mtpa_shift_deg, 2, true).c_str());
        out += line;
      }
    }
  }
  return out;
}

}  // namespace synbench::bench
