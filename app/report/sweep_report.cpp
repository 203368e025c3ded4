// The sweep report's HTML; see sweep_report.hpp and docs/report.md. Numbers are printed at fixed
// precision (angles 0.01 deg, currents 1 mA, powers 0.1 W, efficiency 1e-4) so the page can be
// checked against the analysis JSON.
#include "app/report/sweep_report.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <map>
#include <set>

#include "app/report/report_uncertainty.hpp"
#include "app/report/report_text.hpp"
#include "app/report/svg_plot.hpp"
#include "bench/efficiency_grid.hpp"
#include "db/export.hpp"
#include "drivers/json.hpp"
#include "synbench/version.hpp"

namespace synbench::report {
namespace {

using bench::Configuration;
using bench::label;

bool same(double a, double b) { return std::fabs(a - b) < 1e-6; }

struct Page {
  const ReportInput& in;
  const synbench::Json& json;  // the analysis as JSON: its uncertainty keys (report_uncertainty.hpp)
  std::string body;
  std::size_t figures = 0;

  // "..., sweep #3 'name', encoder / capwm": every figure says what, which sweep, which configuration.
  std::string title(const std::string& what, const Configuration& c) const {
    return what + " — sweep #" + std::to_string(in.sweep.id) + " '" + in.sweep.meta.name + "', " + label(c);
  }
  void figure(const std::string& svg) {
    ++figures;
    body += "<figure>" + svg + "</figure>\n";
  }
};

// The note of a figure with error bars: what they are, or that there is no u to draw.
std::string bars_note(const std::vector<XYSeries>& series, bool hollow) {
  const bool any = std::any_of(series.begin(), series.end(),
                               [](const XYSeries& s) { return std::any_of(s.u.begin(), s.u.end(), [](double u) { return std::isfinite(u); }); });
  return any ? std::string("bars: ±2u, 95 %") + (hollow ? "\nhollow: not significant\nat 95 %" : "") : "no uncertainty stored";
}
const synbench::Json& entry(const synbench::Json& j, const char* section, std::size_t i) {
  static const synbench::Json kNull;
  const auto s = j.find(section);
  if (s == j.end() || !s->contains("entries") || i >= (*s)["entries"].size()) return kNull;
  return (*s)["entries"][i];
}
double u_of(const std::optional<double>& u) { return u.value_or(std::nan("")); }

void figures_of(Page& p, const Configuration& cfg) {
  const auto& a = p.in.analysis;
  // the analysis JSON entry of a curve or delta (to_json keeps the order of a.curves and a.deltas)
  const auto curve_json = [&](const bench::CurveResult* c) -> const synbench::Json& {
    return entry(p.json, "curves", static_cast<std::size_t>(c - a.curves.data()));
  };
  // Efficiency map as measured, and interpolated with iso-lines.
  for (const auto& c : a.efficiency_contours) {
    if (!(c.configuration == cfg)) continue;
    HeatPlot m;
    m.title = p.title("Efficiency map η = P_m / P_dcM at the ME angle [%]", cfg);
    m.x_label = "speed [rpm]";
    m.y_label = "load torque T_L [N m]";
    m.categorical = true;
    const auto grid = bench::measured_efficiency_grid(a.efficiency, cfg);
    m.xs = grid.speed_rpm;
    m.ys = grid.load_Nm;
    m.z = grid.values;
    p.figure(svg_heat(m));
    HeatPlot f;
    f.title = p.title("Efficiency contours (interpolated, iso-efficiency lines)", cfg);
    f.x_label = m.x_label;
    f.y_label = m.y_label;
    f.xs = c.speed_rpm;
    f.ys = c.load_Nm;
    f.z = c.efficiency;
    f.lines = c.lines;
    p.figure(svg_heat(f));
  }
  // MTPA and ME trajectories; I_m and P_dcM against angle per speed.
  std::vector<const bench::CurveResult*> curves;
  for (const auto& c : a.curves)
    if (c.configuration == cfg) curves.push_back(&c);
  std::vector<double> speeds;
  for (const auto* c : curves)
    if (std::none_of(speeds.begin(), speeds.end(), [&](double s) { return same(s, c->speed_rpm); })) speeds.push_back(c->speed_rpm);
  if (!curves.empty()) {
    XYPlot t{p.title("MTPA (solid) and ME (dashed) current angle against load (Fig. 6.20)", cfg), "load torque T_L [N m]",
             "current angle θ_i [deg]", {}};
    for (double s : speeds) {
      XYSeries mtpa{"MTPA " + shortest(s) + " rpm", {}, false}, me{"ME " + shortest(s) + " rpm", {}, true};
      for (const auto* c : curves)
        if (same(c->speed_rpm, s)) {
          mtpa.points.push_back({c->load_Nm, c->mtpa.angle_deg});
          me.points.push_back({c->load_Nm, c->me.angle_deg});
          mtpa.u.push_back(json_number(curve_json(c), "mtpa_angle_u_deg"));
          me.u.push_back(json_number(curve_json(c), "me_angle_u_deg"));
        }
      t.series.push_back(std::move(mtpa));
      t.series.push_back(std::move(me));
    }
    t.note = bars_note(t.series, false);
    p.figure(svg_xy(t));
  }
  std::set<std::size_t> excluded;
  for (const auto& e : a.excluded) excluded.insert(e.record);
  for (double s : speeds) {
    XYPlot im{p.title("I_m against current angle at " + shortest(s) + " rpm", cfg), "current angle θ_i [deg]", "I_m [A]", {}};
    XYPlot pd{p.title("P_dcM against current angle at " + shortest(s) + " rpm", cfg), "current angle θ_i [deg]", "P_dcM [W]", {}};
    for (const auto* c : curves) {
      if (!same(c->speed_rpm, s)) continue;
      std::vector<const bench::PointRecord*> pts;
      for (std::size_t i = 0; i < p.in.rows.size(); ++i) {
        const auto& r = p.in.rows[i].record;
        if (!excluded.count(i) && r.estimator == cfg.estimator && r.pwm == cfg.pwm && same(r.speed_rpm, s) &&
            same(r.load_Nm, c->load_Nm))
          pts.push_back(&r);
      }
      std::sort(pts.begin(), pts.end(), [](auto* l, auto* r) { return l->angle_deg < r->angle_deg; });
      XYSeries a1{shortest(c->load_Nm) + " N m", {}, false}, a2 = a1;
      for (const auto* r : pts) {
        a1.points.push_back({r->angle_deg, r->im_A});
        a2.points.push_back({r->angle_deg, r->pdcm_W});
        a1.u.push_back(u_of(r->im_u_A));
        a2.u.push_back(u_of(r->pdcm_u_W));
      }
      im.series.push_back(std::move(a1));
      pd.series.push_back(std::move(a2));
    }
    im.note = bars_note(im.series, false);
    pd.note = bars_note(pd.series, false);
    p.figure(svg_xy(im));
    p.figure(svg_xy(pd));
  }
  // Position error against load.
  XYPlot pe{p.title("Position error against load, min / mean / max (Figs. 6.13-6.15)", cfg), "load torque T_L [N m]",
            "position error [deg]", {}};
  for (double s : speeds) {
    XYSeries mean{"mean " + shortest(s) + " rpm", {}, false}, lo{"min " + shortest(s) + " rpm", {}, true},
        hi{"max " + shortest(s) + " rpm", {}, true};
    for (const auto& e : a.position_error)
      if (e.configuration == cfg && same(e.speed_rpm, s)) {
        mean.points.push_back({e.load_Nm, e.mean_deg});
        lo.points.push_back({e.load_Nm, e.min_deg});
        hi.points.push_back({e.load_Nm, e.max_deg});
      }
    if (mean.points.empty()) continue;
    pe.series.push_back(std::move(mean));
    pe.series.push_back(std::move(lo));
    pe.series.push_back(std::move(hi));
  }
  if (!pe.series.empty()) p.figure(svg_xy(pe));
  // Deltas against the reference.
  XYPlot di{p.title("ΔI_m on the MTPA trajectory vs reference " + label(a.options.reference) + " (Fig. 6.21)", cfg),
            "load torque T_L [N m]", "ΔI_m [A]", {}};
  XYPlot dp{p.title("ΔP_dcM on the ME trajectory vs reference " + label(a.options.reference) + " (Fig. 6.21)", cfg),
            "load torque T_L [N m]", "ΔP_dcM [W]", {}};
  for (double s : speeds) {
    XYSeries x1{shortest(s) + " rpm", {}, false}, x2 = x1;
    for (std::size_t i = 0; i < a.deltas.size(); ++i) {
      const auto& d = a.deltas[i];
      if (!(d.configuration == cfg && same(d.speed_rpm, s))) continue;
      const auto& j = entry(p.json, "deltas", i);
      const auto& jm = j.is_object() && j.contains("mtpa") ? j["mtpa"] : j;
      const auto& je = j.is_object() && j.contains("me") ? j["me"] : j;
      x1.points.push_back({d.load_Nm, d.mtpa.delta_im_A});
      x2.points.push_back({d.load_Nm, d.me.delta_pdcm_W});
      x1.u.push_back(json_number(jm, "delta_im_u_A"));
      x2.u.push_back(json_number(je, "delta_pdcm_u_W"));
      x1.hollow.push_back(json_bool(jm, "delta_im_significant") == std::optional<bool>(false));
      x2.hollow.push_back(json_bool(je, "delta_pdcm_significant") == std::optional<bool>(false));
    }
    if (x1.points.empty()) continue;
    di.series.push_back(std::move(x1));
    dp.series.push_back(std::move(x2));
  }
  di.note = bars_note(di.series, true);
  dp.note = bars_note(dp.series, true);
  if (!di.series.empty()) {
    p.figure(svg_xy(di));
    p.figure(svg_xy(dp));
  }
  // Histograms.
  for (const auto& h : a.histograms) {
    if (!(h.configuration == cfg)) continue;
    std::vector<Bar> bars;
    for (const auto& b : h.bins) bars.push_back({b.from, b.to, static_cast<double>(b.count)});
    p.figure(svg_bars(p.title("Histogram of " + h.quantity + " (Figs. 6.16-6.19)", cfg), h.quantity + " [" + h.unit + "]",
                      "points", bars));
  }
}

std::string json_block(const synbench::Json& j) {
  return "<pre>" + escape_xml(j.is_null() ? std::string("(none recorded)") : j.dump(2)) + "</pre>";
}

constexpr const char* kStyle = R"(
body{font:15px/1.45 system-ui,sans-serif;color:#14181f;max-width:1100px;margin:2em auto;padding:0 1em}
h1{font-size:1.6em}h2{border-bottom:2px solid #333b47;margin-top:2em}h3{margin-top:1.5em}
table{border-collapse:collapse;margin:.5em 0;font-variant-numeric:tabular-nums}
th,td{border:1px solid #c5cad3;padding:2px 8px;text-align:right}th{background:#eef0f4}td:first-child,th:first-child{text-align:left}
pre{background:#f4f5f8;padding:.6em;overflow:auto;max-height:30em;font-size:13px;white-space:pre-wrap}
figure{margin:1em 0}svg.plot{width:100%;max-width:860px;height:auto;font:11px sans-serif}
svg .t{font-size:13px;font-weight:600}svg .l{font-weight:600}svg .g{stroke:#e3e6eb}svg .f{fill:none;stroke:#333b47}
svg .v{font-size:10px;fill:#000;paint-order:stroke;stroke:#fff;stroke-width:2px}
svg .iso-label{font-size:11px;font-weight:700;paint-order:stroke;stroke:#fff;stroke-width:3px}
svg .note{font-size:10px;fill:#4a5361}svg .eb{stroke-width:1.2}
)";

}  // namespace

std::string report_base_name(const db::Sweep& sweep, const std::string& generated_at) {
  std::string slug;
  for (char c : sweep.meta.name) {
    const bool alnum = (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9');
    if (alnum) slug += c;
    else if (c >= 'A' && c <= 'Z') slug += static_cast<char>(c - 'A' + 'a');
    else if (!slug.empty() && slug.back() != '-') slug += '-';
    if (slug.size() >= 40) break;
  }
  while (!slug.empty() && slug.back() == '-') slug.pop_back();
  if (slug.empty()) slug = "sweep";
  return "synbench-report-" + std::to_string(sweep.id) + "-" + slug + "-" + generated_at.substr(0, 10);
}

std::string render_report(const ReportInput& in) {
  const auto& s = in.sweep;
  const auto& a = in.analysis;
  const synbench::Json json = bench::to_json(a);
  Page p{in, json, {}, 0};
  const std::string name = "Sweep #" + std::to_string(s.id) + " '" + s.meta.name + "'";
  std::string& b = p.body;
  b += "<h1>" + escape_xml(name) + "</h1>\n<p class=\"generated\">Report generated <time>" + escape_xml(in.context.generated_at) +
       "</time> by synbench " + escape_xml(kVersion) + " on " + escape_xml(in.context.host) + ".</p>\n";
  b += "<h2 id=\"sweep\">Sweep</h2>\n<table id=\"sweep-table\">";
  const auto row = [&b](const std::string& k, const std::string& v) { b += "<tr><th>" + escape_xml(k) + "</th>" + td(v) + "</tr>"; };
  row("id", std::to_string(s.id));
  row("name", s.meta.name);
  row("state", std::string(db::name(s.state)));
  row("created", s.created_at);
  row("started", s.started_at.value_or("–"));
  row("finished", s.finished_at.value_or("–"));
  row("points stored / planned", std::to_string(s.points_stored) + " / " + std::to_string(s.meta.total_points));
  row("points used in the analysis", std::to_string(a.used) + " of " + std::to_string(a.records));
  if (s.last_error) row("last error", *s.last_error);
  b += "</table>\n<h2 id=\"metadata\">Bench and software</h2>\n<table id=\"meta-table\">";
  row("synbench version that ran the sweep", s.meta.software_version);
  row("synbench version of this report", kVersion);
  row("host of this report", in.context.host);
  row("bench", s.meta.bench_config.is_null() ? "none recorded" : "the configuration recorded with the sweep, below");
  row("reference configuration (deltas)", label(a.options.reference));
  b += "</table>\n<h3>Bench configuration (a bench config, or the twin's config)</h3>" + json_block(s.meta.bench_config) + "<h3>Device profiles</h3>" +
       json_block(s.meta.profiles) + "<h3>Calibration</h3>" + json_block(s.meta.calibration) +
       "\n<h2 id=\"plan\">Plan</h2>" + json_block(s.meta.plan);

  std::vector<Configuration> configs;
  for (const auto& c : a.curves)
    if (std::find(configs.begin(), configs.end(), c.configuration) == configs.end()) configs.push_back(c.configuration);
  b += uncertainty_section(json, in.rows);
  b += "\n<h2 id=\"figures\">Figures</h2>\n";
  if (configs.empty()) b += "<p>No point of this sweep is usable: nothing to draw.</p>";
  for (const auto& cfg : configs) {
    b += "<h3>" + escape_xml(label(cfg)) + "</h3>\n";
    figures_of(p, cfg);
  }

  b += "\n<h2 id=\"tables\">Tables</h2>\n<h3>MTPA and ME optima per configuration, speed and load</h3>\n"
       "<table id=\"optima\"><thead><tr><th>estimator</th><th>pwm</th><th>speed_rpm</th><th>load_Nm</th><th>points</th>"
       "<th>MTPA angle_deg</th><th>MTPA im_A</th><th>MTPA pdcm_W</th><th>MTPA efficiency</th>"
       "<th>ME angle_deg</th><th>ME im_A</th><th>ME pdcm_W</th><th>ME efficiency</th>"
       "<th>MTPA angle_u_deg</th><th>MTPA im_u_A</th><th>ME angle_u_deg</th><th>ME pdcm_u_W</th><th>ME efficiency_u</th>"
       "<th>me_minus_mtpa_deg</th><th>me_minus_mtpa_u_deg</th><th>ME − MTPA significant at 95 %</th></tr></thead><tbody>";
  const auto opt = [](const bench::CurveOptimum& o) {
    return td(fixed(o.angle_deg, 2)) + td(fixed(o.im_A, 3)) + td(fixed(o.pdcm_W, 1)) +
           td(o.pdcm_W > 0 ? fixed(o.efficiency, 4) : "–");
  };
  for (std::size_t i = 0; i < a.curves.size(); ++i) {
    const auto& c = a.curves[i];
    const auto& j = entry(json, "curves", i);
    const auto& jm = j.is_object() && j.contains("mtpa") ? j["mtpa"] : j;
    const auto& je = j.is_object() && j.contains("me") ? j["me"] : j;
    b += "<tr>" + td(std::string(drivers::name(c.configuration.estimator))) + td(std::string(drivers::name(c.configuration.pwm))) +
         td(shortest(c.speed_rpm)) + td(shortest(c.load_Nm)) + td(std::to_string(c.points)) + opt(c.mtpa) + opt(c.me) +
         td(u_text(json_number(j, "mtpa_angle_u_deg"))) + td(u_text(json_number(jm, "im_u_A"))) +
         td(u_text(json_number(j, "me_angle_u_deg"))) + td(u_text(json_number(je, "pdcm_u_W"))) + td(u_text(json_number(je, "efficiency_u"))) +
         td(fixed(json_number(j, "me_minus_mtpa_deg"), 2)) + td(u_text(json_number(j, "me_minus_mtpa_u_deg"))) +
         td(significance_text(json_bool(j, "me_minus_mtpa_significant"))) + "</tr>";
  }
  b += "</tbody></table>\n" + deltas_table(json);
  for (const auto& cfg : configs) {
    const auto grid = bench::measured_efficiency_grid(a.efficiency, cfg);
    b += "<h3>Efficiency at the ME angle, speed x load, " + escape_xml(label(cfg)) + "</h3>\n<table class=\"eta-grid\" data-estimator=\"" +
         std::string(drivers::name(cfg.estimator)) + "\" data-pwm=\"" + std::string(drivers::name(cfg.pwm)) +
         "\"><thead><tr><th>speed_rpm \\ load_Nm</th>";
    for (double l : grid.load_Nm) b += "<th>" + shortest(l) + "</th>";
    b += "</tr></thead><tbody>";
    for (std::size_t k = 0; k < grid.speed_rpm.size(); ++k) {  // rows: speed, as the analysis' efficiency_map
      b += "<tr><th>" + shortest(grid.speed_rpm[k]) + "</th>";
      for (std::size_t r = 0; r < grid.load_Nm.size(); ++r) b += td(grid.values[r][k] ? fixed(*grid.values[r][k], 4) : "–");
      b += "</tr>";
    }
    b += "</tbody></table>\n";
  }
  b += efficiency_u_grids(json);
  b += "\n<h2 id=\"exclusions\">Exclusions</h2>\n";
  if (a.excluded.empty()) b += "<p>No point was left out.</p>";
  else {
    b += "<table id=\"excluded\"><thead><tr><th>record</th><th>configuration</th><th>speed_rpm</th><th>load_Nm</th>"
         "<th>angle_deg</th><th>reasons</th></tr></thead><tbody>";
    for (const auto& e : a.excluded) {
      std::string reasons;
      for (const auto& r : e.reasons) reasons += (reasons.empty() ? "" : ", ") + r;
      b += "<tr>" + td(std::to_string(e.record)) + td(label(e.configuration)) + td(shortest(e.speed_rpm)) +
           td(shortest(e.load_Nm)) + td(shortest(e.angle_deg)) + td(reasons) + "</tr>";
    }
    b += "</tbody></table>";
  }
  return "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>synbench report: " + escape_xml(name) +
         "</title><style>" + kStyle + "</style></head><body>\n" + b + "\n<p class=\"figures\">" +
         std::to_string(p.figures) + " figures.</p></body></html>\n";
}

db::Result<SweepReport> make_sweep_report(db::Store& store, std::int64_t sweep_id, const ReportContext& context) {
  auto sweep = store.get_sweep(sweep_id);
  if (!sweep) return sweep.error();
  auto rows = store.points(sweep_id);
  if (!rows) return rows.error();
  std::vector<bench::PointRecord> records;
  records.reserve(rows->size());
  for (const auto& r : *rows) records.push_back(r.record);
  ReportInput in{*sweep, *rows, bench::analyze(records), context};
  SweepReport out;
  out.base_name = report_base_name(in.sweep, context.generated_at);
  out.html = render_report(in);
  out.csv = db::points_to_csv(*rows);
  return out;
}

ReportContext current_context() {
  ReportContext c;
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  c.generated_at = buf;
  char host[256] = {};
  if (gethostname(host, sizeof host - 1) != 0) host[0] = '\0';
  c.host = host[0] ? host : "unknown host";
  return c;
}

}  // namespace synbench::report
