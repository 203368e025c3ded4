// JSON form of an analysis (docs/analysis.md): every section an object with a description, the
// thesis figure it reproduces and its entries; units in the key names; configurations as
// "estimator" and "pwm" fields as in the point record.
#include "drivers/json.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "bench/analysis.hpp"
#include "bench/efficiency_grid.hpp"

namespace synbench::bench {
namespace {

using ojson = synbench::Json;

// A JSON document must not carry NaN or infinities (nlohmann writes them as null anyway; this
// makes it explicit and keeps the C++ side honest).
ojson number(double v) { return std::isfinite(v) ? ojson(v) : ojson(nullptr); }
ojson number(const std::optional<double>& v) { return v ? number(*v) : ojson(nullptr); }
ojson flag(const std::optional<bool>& v) { return v ? ojson(*v) : ojson(nullptr); }

void put_configuration(ojson& j, const Configuration& c) {
  j["estimator"] = std::string(drivers::name(c.estimator));
  j["pwm"] = std::string(drivers::name(c.pwm));
}

ojson configuration(const Configuration& c) {
  ojson j = ojson::object();
  put_configuration(j, c);
  return j;
}

ojson optimum(const CurveOptimum& o) {
  ojson j = ojson::object();
  j["angle_deg"] = number(o.angle_deg);
  j["im_A"] = number(o.im_A);
  j["pdcm_W"] = number(o.pdcm_W);
  j["pm_W"] = number(o.pm_W);
  j["efficiency"] = o.pdcm_W > 0 ? number(o.efficiency) : ojson(nullptr);
  j["refined"] = o.refined;
  j["at_edge"] = o.at_edge;
  j["im_u_A"] = number(o.im_u_A);
  j["im_u_repeat_A"] = number(o.im_u_repeat_A);
  j["pdcm_u_W"] = number(o.pdcm_u_W);
  j["pdcm_u_repeat_W"] = number(o.pdcm_u_repeat_W);
  j["pm_u_W"] = number(o.pm_u_W);
  j["efficiency_u"] = number(o.efficiency_u);
  j["efficiency_u_repeat"] = number(o.efficiency_u_repeat);
  return j;
}

ojson delta(const TrajectoryDelta& d) {
  ojson j = ojson::object();
  j["delta_angle_deg"] = number(d.delta_angle_deg);
  j["delta_im_A"] = number(d.delta_im_A);
  j["delta_pdcm_W"] = number(d.delta_pdcm_W);
  j["delta_angle_u_deg"] = number(d.delta_angle_u_deg);
  j["delta_im_u_A"] = number(d.delta_im_u_A);
  j["delta_pdcm_u_W"] = number(d.delta_pdcm_u_W);
  j["delta_angle_significant"] = flag(d.delta_angle_significant);
  j["delta_im_significant"] = flag(d.delta_im_significant);
  j["delta_pdcm_significant"] = flag(d.delta_pdcm_significant);
  return j;
}

// A measured grid (rows = load) served rows = speed, null where not measured.
ojson grid_matrix(const MeasuredGrid& g) {
  ojson matrix = ojson::array();
  for (std::size_t i = 0; i < g.speed_rpm.size(); ++i) {
    ojson row = ojson::array();
    for (std::size_t k = 0; k < g.load_Nm.size(); ++k) row.push_back(g.values[k][i] ? number(*g.values[k][i]) : ojson(nullptr));
    matrix.push_back(row);
  }
  return matrix;
}

ojson section(const char* description, const char* figures) {
  ojson j = ojson::object();
  j["description"] = description;
  j["thesis_figures"] = figures ? ojson(figures) : ojson(nullptr);
  return j;
}

// How many of the known differences are significant at 95 %: what a closing note quotes.
ojson counted(std::size_t known, std::size_t significant) {
  return {{"known", known}, {"significant", significant}};
}

ojson uncertainty_summary(const Analysis& a) {
  ojson u = section(
      "Standard uncertainties (k = 1, GUM) propagated from the points' uncertainties (record fields *_u*). "
      "Per curve, Monte Carlo (JCGM 101): every point's im_A, pdcm_W and pm_W drawn from a normal "
      "distribution around its value with its point-to-point (repeat) standard uncertainty, the refinement "
      "redone per draw; an optimum's angle u is the SD of the drawn angles (the systematic parts shift a whole "
      "curve and do not move its minimum); a value's u at an optimum combines the drawn SD with the points' "
      "systematic part sqrt(u^2 - u_repeat^2). im and pdcm noise are drawn independently. ME minus MTPA: "
      "SD of the drawn differences, significant when 0 lies outside their central 95 % interval. Deltas "
      "against the reference: the two optima's repeat parts in quadrature (one bench: the systematic parts "
      "cancel; not valid between two benches), significant when |delta| > 1.96 u. Null wherever a point "
      "lacks an uncertainty, and for an angle whose optimum is at an edge or not refined.",
      nullptr);
  ojson method = ojson::object();
  method["propagation"] = "monte_carlo";
  method["draws"] = a.options.uncertainty_draws;
  method["seed"] = a.options.uncertainty_seed;
  method["coverage"] = 0.95;
  method["delta_significance"] = "abs(delta) > 1.96 u";
  method["me_minus_mtpa_significance"] = "0 outside the central 95 % interval of the draws";
  u["method"] = method;
  std::size_t known = 0, significant = 0;
  for (const auto& c : a.curves)
    if (c.me_minus_mtpa_significant) {
      ++known;
      if (*c.me_minus_mtpa_significant) ++significant;
    }
  u["me_minus_mtpa"] = {{"curves", a.curves.size()}, {"known", known}, {"significant", significant}};
  ojson deltas = ojson::object();
  deltas["entries"] = a.deltas.size();
  const auto trajectory = [&](TrajectoryDelta DeltaResult::*t) {
    std::size_t k[3] = {0, 0, 0}, s[3] = {0, 0, 0};
    for (const auto& d : a.deltas) {
      const std::optional<bool> f[3] = {(d.*t).delta_angle_significant, (d.*t).delta_im_significant,
                                        (d.*t).delta_pdcm_significant};
      for (std::size_t q = 0; q < 3; ++q)
        if (f[q]) {
          ++k[q];
          if (*f[q]) ++s[q];
        }
    }
    ojson x = ojson::object();
    x["delta_angle_deg"] = counted(k[0], s[0]);
    x["delta_im_A"] = counted(k[1], s[1]);
    x["delta_pdcm_W"] = counted(k[2], s[2]);
    return x;
  };
  deltas["mtpa"] = trajectory(&DeltaResult::mtpa);
  deltas["me"] = trajectory(&DeltaResult::me);
  u["deltas"] = deltas;
  std::size_t cells_known = 0;
  for (const auto& c : a.efficiency)
    if (c.efficiency_u) ++cells_known;
  u["efficiency_map"] = {{"cells", a.efficiency.size()}, {"known", cells_known}};
  return u;
}

}  // namespace

ojson to_json(const Analysis& a) {
  ojson j = ojson::object();
  j["schema"] = "synbench.analysis/1";

  const auto& o = a.options;
  ojson opt = ojson::object();
  opt["reference"] = configuration(o.reference);
  opt["exclude_unstable"] = o.exclude_unstable;
  opt["exclude_faulted"] = o.exclude_faulted;
  opt["exclude_voltage_limited"] = o.exclude_voltage_limited;
  opt["exclude_below_min_speed"] = o.exclude_below_min_speed;
  opt["exclude_lock_lost"] = o.exclude_lock_lost;
  opt["exclude_angle_off"] = o.exclude_angle_off;
  opt["bin_width"] = {{"pos_err_mean_deg", o.pos_err_bin_deg},
                      {"ld_err_pct", o.ld_err_bin_pct},
                      {"lq_err_pct", o.lq_err_bin_pct},
                      {"rs_err_pct", o.rs_err_bin_pct}};
  j["options"] = opt;

  ojson pts = section("Records analysed; flagged ones are left out of every result below.", nullptr);
  pts["records"] = a.records;
  pts["used"] = a.used;
  ojson ex = ojson::array();
  for (const auto& e : a.excluded) {
    ojson x = ojson::object();
    x["record"] = e.record;
    put_configuration(x, e.configuration);
    x["speed_rpm"] = e.speed_rpm;
    x["load_Nm"] = e.load_Nm;
    x["angle_deg"] = e.angle_deg;
    x["reasons"] = e.reasons;
    ex.push_back(x);
  }
  pts["excluded"] = ex;
  j["points"] = pts;

  ojson curves = section(
      "Per configuration, speed and load: the MTPA angle (minimum im_A over angle_deg) and the ME angle "
      "(minimum pdcm_W), refined by the parabola through the smallest sample and its neighbours, with im_A, "
      "pdcm_W, pm_W and efficiency read there. at_edge: the smallest sample is the first or last angle, so "
      "the optimum may lie outside the range measured (not refined).",
      "6.20");
  ojson ce = ojson::array();
  for (const auto& c : a.curves) {
    ojson x = ojson::object();
    put_configuration(x, c.configuration);
    x["speed_rpm"] = c.speed_rpm;
    x["load_Nm"] = c.load_Nm;
    x["points"] = c.points;
    x["angles_deg"] = c.angles_deg;
    x["mtpa"] = optimum(c.mtpa);
    x["me"] = optimum(c.me);
    x["mtpa_angle_u_deg"] = number(c.mtpa.angle_u_deg);
    x["me_angle_u_deg"] = number(c.me.angle_u_deg);
    x["me_minus_mtpa_deg"] = number(c.me_minus_mtpa_deg);
    x["me_minus_mtpa_u_deg"] = number(c.me_minus_mtpa_u_deg);
    x["me_minus_mtpa_significant"] = flag(c.me_minus_mtpa_significant);
    ce.push_back(x);
  }
  curves["entries"] = ce;
  j["curves"] = curves;

  ojson deltas = section(
      "Configuration minus reference at the same speed and load, on the MTPA trajectory (at each one's own "
      "MTPA angle) and on the ME trajectory (at each one's own ME angle).",
      "6.21");
  deltas["reference"] = configuration(o.reference);
  ojson de = ojson::array();
  for (const auto& d : a.deltas) {
    ojson x = ojson::object();
    put_configuration(x, d.configuration);
    x["speed_rpm"] = d.speed_rpm;
    x["load_Nm"] = d.load_Nm;
    x["mtpa"] = delta(d.mtpa);
    x["me"] = delta(d.me);
    de.push_back(x);
  }
  deltas["entries"] = de;
  j["deltas"] = deltas;

  ojson hist = section(
      "Per configuration, over all points used: counts of a record field in bins [from, to) whose edges "
      "are multiples of bin_width, contiguous from the lowest to the highest occupied bin. from, to and "
      "bin_width are in the field's unit (unit).",
      "6.16-6.19");
  ojson he = ojson::array();
  for (const auto& h : a.histograms) {
    ojson x = ojson::object();
    put_configuration(x, h.configuration);
    x["quantity"] = h.quantity;
    x["unit"] = h.unit;
    x["bin_width"] = h.bin_width;
    x["count"] = h.count;
    x["min"] = number(h.min);
    x["mean"] = number(h.mean);
    x["max"] = number(h.max);
    ojson bins = ojson::array();
    for (const auto& b : h.bins) bins.push_back({{"from", b.from}, {"to", b.to}, {"count", b.count}});
    x["bins"] = bins;
    he.push_back(x);
  }
  hist["entries"] = he;
  j["histograms"] = hist;

  // One panel per configuration and speed, load on the horizontal axis.
  ojson pe = section(
      "Position error against load, one panel per configuration and speed: min_deg, mean_deg, max_deg over "
      "the angles measured of each point's window-mean error (pos_err_mean_deg); window_min_deg and "
      "window_max_deg are the extremes seen inside the windows.",
      "6.13-6.15");
  ojson panels = ojson::array();
  std::map<std::pair<Configuration, long long>, std::size_t> panel_of;
  for (const auto& p : a.position_error) {
    const std::pair<Configuration, long long> k{p.configuration, std::llround(p.speed_rpm * 1e6)};
    auto it = panel_of.find(k);
    if (it == panel_of.end()) {
      ojson panel = ojson::object();
      put_configuration(panel, p.configuration);
      panel["speed_rpm"] = p.speed_rpm;
      panel["loads"] = ojson::array();
      it = panel_of.emplace(k, panels.size()).first;
      panels.push_back(panel);
    }
    ojson x = ojson::object();
    x["load_Nm"] = p.load_Nm;
    x["points"] = p.points;
    x["min_deg"] = number(p.min_deg);
    x["mean_deg"] = number(p.mean_deg);
    x["max_deg"] = number(p.max_deg);
    x["window_min_deg"] = number(p.window_min_deg);
    x["window_max_deg"] = number(p.window_max_deg);
    panels[it->second]["loads"].push_back(x);
  }
  pe["entries"] = panels;
  j["position_error"] = pe;

  // Efficiency map: a speed x load matrix per configuration (null where not measured) for
  // drawing, and the cells with their ME angle and powers.
  ojson em = section(
      "Per configuration: efficiency = pm_W / pdcm_W at the ME angle over speed x load. efficiency[i][j] "
      "belongs to speeds_rpm[i] and loads_Nm[j]; null where that curve was not measured.",
      nullptr);
  ojson maps = ojson::array();
  std::map<Configuration, std::vector<const EfficiencyCell*>> by_config;
  for (const auto& c : a.efficiency) by_config[c.configuration].push_back(&c);
  for (const auto& [config, cells] : by_config) {
    // The one measured grid (bench/efficiency_grid.hpp, rows = load) served here rows = speed.
    const MeasuredGrid g = measured_efficiency_grid(a.efficiency, config);
    const ojson matrix = grid_matrix(g);
    ojson m = ojson::object();
    put_configuration(m, config);
    m["speeds_rpm"] = g.speed_rpm;
    m["loads_Nm"] = g.load_Nm;
    m["efficiency"] = matrix;
    m["efficiency_u"] = grid_matrix(measured_efficiency_grid(a.efficiency, config, &EfficiencyCell::efficiency_u));
    m["efficiency_u_repeat"] =
        grid_matrix(measured_efficiency_grid(a.efficiency, config, &EfficiencyCell::efficiency_u_repeat));
    ojson list = ojson::array();
    for (const auto* c : cells) {
      ojson x = ojson::object();
      x["speed_rpm"] = c->speed_rpm;
      x["load_Nm"] = c->load_Nm;
      x["angle_deg"] = number(c->angle_deg);
      x["pm_W"] = number(c->pm_W);
      x["pdcm_W"] = number(c->pdcm_W);
      x["efficiency"] = c->pdcm_W > 0 ? number(c->efficiency) : ojson(nullptr);
      x["refined"] = c->refined;
      x["pm_u_W"] = number(c->pm_u_W);
      x["pdcm_u_W"] = number(c->pdcm_u_W);
      x["efficiency_u"] = number(c->efficiency_u);
      x["efficiency_u_repeat"] = number(c->efficiency_u_repeat);
      list.push_back(x);
    }
    m["cells"] = list;
    maps.push_back(m);
  }
  em["entries"] = maps;
  j["efficiency_map"] = em;

  ojson ec = section(
      "Per configuration: the efficiency map interpolated bilinearly inside the measured speed x load grid "
      "(never outside it, and not in a cell with a corner not measured: null there), efficiency[i][j] at "
      "load_Nm[i] and speed_rpm[j]; and its iso-efficiency lines by marching squares at levels, each line "
      "a list of segments [[speed_rpm, load_Nm], [speed_rpm, load_Nm]].",
      nullptr);
  ojson ce2 = ojson::array();
  for (const auto& c : a.efficiency_contours) {
    ojson x = ojson::object();
    put_configuration(x, c.configuration);
    x["speed_rpm"] = c.speed_rpm;
    x["load_Nm"] = c.load_Nm;
    ojson field = ojson::array();
    for (const auto& row : c.efficiency) {
      ojson r = ojson::array();
      for (const auto& v : row) r.push_back(v ? number(*v) : ojson(nullptr));
      field.push_back(r);
    }
    x["efficiency"] = field;
    x["levels"] = c.levels;
    ojson lines = ojson::array();
    for (const auto& l : c.lines) {
      ojson segs = ojson::array();
      for (const auto& s : l.segments)
        segs.push_back(ojson::array({ojson::array({s[0][0], s[0][1]}), ojson::array({s[1][0], s[1][1]})}));
      lines.push_back({{"level", l.level}, {"segments", segs}});
    }
    x["lines"] = lines;
    ce2.push_back(x);
  }
  ec["entries"] = ce2;
  j["efficiency_contours"] = ec;
  j["uncertainty"] = uncertainty_summary(a);
  return j;
}

}  // namespace synbench::bench
