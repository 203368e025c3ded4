// Curves, optima, deltas, histograms, position error and efficiency map from point records.
// (The JSON form is in analysis_json.cpp.)
#include "bench/analysis.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <tuple>

#include "bench/analysis_fit.hpp"
#include "bench/analysis_uncertainty.hpp"

namespace synbench::bench {
namespace {

// Setpoints come from the plan, so equal setpoints are equal numbers; the rounding only absorbs
// a decimal round trip through a database or CSV.
long long setpoint_key(double v) { return std::llround(v * 1e6); }

using CurveKey = std::tuple<Configuration, long long, long long>;

CurveKey key_of(const PointRecord& r) {
  return {Configuration{r.estimator, r.pwm}, setpoint_key(r.speed_rpm), setpoint_key(r.load_Nm)};
}


// One quantity's uncertainties per distinct angle while repeats are averaged: the repeat parts
// of a mean of n add in quadrature over n, the systematic parts (common to the repeats) average.
struct UncertaintySum {
  bool repeat_known = true, known = true;
  std::vector<double> repeat2, systematic;
  void start() {
    repeat2.push_back(0);
    systematic.push_back(0);
  }
  void add(const std::optional<double>& u, const std::optional<double>& repeat) {
    repeat_known = repeat_known && repeat && std::isfinite(*repeat);
    known = known && repeat_known && u && std::isfinite(*u);
    if (repeat_known) repeat2.back() += *repeat * *repeat;
    if (known) systematic.back() += std::sqrt(std::max(0.0, *u * *u - *repeat * *repeat));
  }
  SampleUncertainty mean(const std::vector<std::size_t>& n) const {
    SampleUncertainty out;
    if (!repeat_known) return out;
    for (std::size_t k = 0; k < n.size(); ++k) out.repeat.push_back(std::sqrt(repeat2[k]) / static_cast<double>(n[k]));
    if (!known) return out;
    for (std::size_t k = 0; k < n.size(); ++k) out.systematic.push_back(systematic[k] / static_cast<double>(n[k]));
    return out;
  }
};

// The record carries pm_W's combined u but not its repeat part; efficiency = pm_W / pdcm_W with
// independent meters gives u_eff^2 = (u_pm / pdcm)^2 + (eff u_pdcm / pdcm)^2, solved for u_pm.
std::optional<double> pm_u_repeat_W(const PointRecord& r) {
  if (!r.efficiency_u_repeat || !r.pdcm_u_repeat_W || !(r.pdcm_W > 0)) return std::nullopt;
  const double eff = r.pm_W / r.pdcm_W;
  const double a = r.pdcm_W * *r.efficiency_u_repeat, b = eff * *r.pdcm_u_repeat_W;
  return std::sqrt(std::max(0.0, a * a - b * b));
}

std::uint64_t mix(std::uint64_t h, std::uint64_t v) {
  // splitmix64's finaliser over h + v: distinct curves get unrelated streams.
  std::uint64_t x = h + v + 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// A seed per curve from the analysis' seed and the curve's key, so a curve's result does not
// depend on which other curves are analysed with it.
std::uint64_t curve_seed(std::uint64_t seed, const CurveKey& key) {
  const auto& [config, speed, load] = key;
  std::uint64_t h = mix(seed, static_cast<std::uint64_t>(config.estimator));
  h = mix(h, static_cast<std::uint64_t>(config.pwm));
  h = mix(h, static_cast<std::uint64_t>(speed));
  return mix(h, static_cast<std::uint64_t>(load));
}

struct Quantity {
  const char* name;
  const char* unit;
  std::optional<double> PointRecord::*field;
  double AnalysisOptions::*width;
};

const Quantity kQuantities[] = {
    {"pos_err_mean_deg", "deg", &PointRecord::pos_err_mean_deg, &AnalysisOptions::pos_err_bin_deg},
    {"ld_err_pct", "%", &PointRecord::ld_err_pct, &AnalysisOptions::ld_err_bin_pct},
    {"lq_err_pct", "%", &PointRecord::lq_err_pct, &AnalysisOptions::lq_err_bin_pct},
    {"rs_err_pct", "%", &PointRecord::rs_err_pct, &AnalysisOptions::rs_err_bin_pct},
};

}  // namespace

std::vector<HistogramBin> histogram_bins(const std::vector<double>& values, double width) {
  std::vector<HistogramBin> bins;
  if (!(width > 0)) return bins;
  std::map<long long, std::size_t> counts;
  for (double v : values) {
    if (!std::isfinite(v)) continue;
    // The small slack keeps a value on an edge (1.5 with 0.5 bins) in the bin the edge starts,
    // even when it arrives as 1.4999999999999998.
    ++counts[static_cast<long long>(std::floor(v / width + 1e-9))];
  }
  if (counts.empty()) return bins;
  for (long long k = counts.begin()->first; k <= counts.rbegin()->first; ++k) {
    const auto it = counts.find(k);
    bins.push_back({static_cast<double>(k) * width, static_cast<double>(k + 1) * width,
                    it == counts.end() ? 0 : it->second});
  }
  return bins;
}

Analysis analyze(const std::vector<PointRecord>& records, const AnalysisOptions& options) {
  Analysis a;
  a.options = options;
  a.records = records.size();

  // 1. Leave flagged points out, saying why.
  std::vector<std::size_t> used;
  for (std::size_t i = 0; i < records.size(); ++i) {
    const auto& r = records[i];
    std::vector<std::string> reasons;
    if (options.exclude_unstable && r.unstable) reasons.push_back("unstable");
    if (options.exclude_faulted && r.fault) reasons.push_back("fault: " + *r.fault);
    if (options.exclude_voltage_limited && r.voltage_limited) reasons.push_back("voltage_limited");
    if (options.exclude_below_min_speed && r.below_min_speed) reasons.push_back("below_min_speed");
    if (options.exclude_lock_lost && r.lock_lost) reasons.push_back("lock_lost");
    if (options.exclude_angle_off && r.angle_off) reasons.push_back("angle_off");
    if (reasons.empty()) {
      used.push_back(i);
    } else {
      a.excluded.push_back({i, {r.estimator, r.pwm}, r.speed_rpm, r.load_Nm, r.angle_deg, std::move(reasons)});
    }
  }
  a.used = used.size();

  // 2. Curves: the used points of one (configuration, speed, load), by angle.
  std::map<CurveKey, std::vector<std::size_t>> curves;
  for (auto i : used) curves[key_of(records[i])].push_back(i);

  std::map<CurveKey, std::size_t> curve_index;
  for (auto& [key, idx] : curves) {
    std::sort(idx.begin(), idx.end(), [&](auto l, auto r) { return records[l].angle_deg < records[r].angle_deg; });
    CurveResult c;
    c.configuration = std::get<0>(key);
    c.speed_rpm = records[idx.front()].speed_rpm;
    c.load_Nm = records[idx.front()].load_Nm;
    c.points = idx.size();
    // Repeats at one angle are averaged: a re-measured point counts once.
    std::vector<double> im, pdcm, pm;
    std::vector<std::size_t> n;
    UncertaintySum im_u, pdcm_u, pm_u, eff_u;
    for (auto i : idx) {
      const auto& r = records[i];
      if (!c.angles_deg.empty() && std::fabs(r.angle_deg - c.angles_deg.back()) < 1e-6) {
        im.back() += r.im_A;
        pdcm.back() += r.pdcm_W;
        pm.back() += r.pm_W;
        ++n.back();
      } else {
        c.angles_deg.push_back(r.angle_deg);
        im.push_back(r.im_A);
        pdcm.push_back(r.pdcm_W);
        pm.push_back(r.pm_W);
        n.push_back(1);
        for (auto* u : {&im_u, &pdcm_u, &pm_u, &eff_u}) u->start();
      }
      im_u.add(r.im_u_A, r.im_u_repeat_A);
      pdcm_u.add(r.pdcm_u_W, r.pdcm_u_repeat_W);
      pm_u.add(r.pm_u_W, pm_u_repeat_W(r));
      eff_u.add(r.efficiency_u, r.efficiency_u_repeat);
    }
    for (std::size_t k = 0; k < n.size(); ++k) {
      const double d = static_cast<double>(n[k]);
      im[k] /= d;
      pdcm[k] /= d;
      pm[k] /= d;
    }
    c.mtpa = curve_optimum(c.angles_deg, im, pdcm, pm, true);
    c.me = curve_optimum(c.angles_deg, im, pdcm, pm, false);
    c.me_minus_mtpa_deg = c.me.angle_deg - c.mtpa.angle_deg;
    // 2a. Their uncertainties from the points' (JCGM 101 Monte Carlo over the curve).
    const CurveSamples samples{c.angles_deg,  im,          pdcm,        pm,
                               im_u.mean(n), pdcm_u.mean(n), pm_u.mean(n), eff_u.mean(n)};
    propagate_curve_uncertainty(c, samples, {options.uncertainty_draws, curve_seed(options.uncertainty_seed, key)});
    curve_index[key] = a.curves.size();
    a.curves.push_back(std::move(c));
  }

  // 3. Deltas against the reference on both optimal trajectories (Fig. 6.21).
  for (const auto& [key, ci] : curve_index) {
    if (std::get<0>(key) == options.reference) continue;
    const auto ref = curve_index.find({options.reference, std::get<1>(key), std::get<2>(key)});
    if (ref == curve_index.end()) continue;
    const auto& c = a.curves[ci];
    const auto& r = a.curves[ref->second];
    auto delta = [](const CurveOptimum& x, const CurveOptimum& y) {
      TrajectoryDelta d;
      d.delta_angle_deg = x.angle_deg - y.angle_deg;
      d.delta_im_A = x.im_A - y.im_A;
      d.delta_pdcm_W = x.pdcm_W - y.pdcm_W;
      add_delta_uncertainty(d, x, y);
      return d;
    };
    a.deltas.push_back({c.configuration, c.speed_rpm, c.load_Nm, delta(c.mtpa, r.mtpa), delta(c.me, r.me)});
  }

  // 4. Histograms over all used points of a configuration (Figs. 6.16 to 6.19).
  std::map<Configuration, std::vector<std::size_t>> by_config;
  for (auto i : used) by_config[Configuration{records[i].estimator, records[i].pwm}].push_back(i);
  for (const auto& [config, idx] : by_config) {
    for (const auto& q : kQuantities) {
      std::vector<double> values;
      for (auto i : idx)
        if (const auto& v = records[i].*q.field; v && std::isfinite(*v)) values.push_back(*v);
      if (values.empty()) continue;
      Histogram h;
      h.configuration = config;
      h.quantity = q.name;
      h.unit = q.unit;
      h.bin_width = options.*q.width;
      h.count = values.size();
      h.min = *std::min_element(values.begin(), values.end());
      h.max = *std::max_element(values.begin(), values.end());
      double sum = 0;
      for (double v : values) sum += v;
      h.mean = sum / static_cast<double>(values.size());
      h.bins = histogram_bins(values, h.bin_width);
      a.histograms.push_back(std::move(h));
    }
  }

  // 5. Position error against load per speed (Figs. 6.13 to 6.15): over the angles of a curve.
  for (const auto& [key, idx] : curves) {
    PositionErrorResult p;
    p.configuration = std::get<0>(key);
    p.speed_rpm = records[idx.front()].speed_rpm;
    p.load_Nm = records[idx.front()].load_Nm;
    double sum = 0;
    p.min_deg = p.window_min_deg = std::numeric_limits<double>::infinity();
    p.max_deg = p.window_max_deg = -std::numeric_limits<double>::infinity();
    for (auto i : idx) {
      const auto& r = records[i];
      if (!r.pos_err_mean_deg) continue;
      ++p.points;
      sum += *r.pos_err_mean_deg;
      p.min_deg = std::min(p.min_deg, *r.pos_err_mean_deg);
      p.max_deg = std::max(p.max_deg, *r.pos_err_mean_deg);
      p.window_min_deg = std::min(p.window_min_deg, r.pos_err_min_deg.value_or(*r.pos_err_mean_deg));
      p.window_max_deg = std::max(p.window_max_deg, r.pos_err_max_deg.value_or(*r.pos_err_mean_deg));
    }
    if (p.points == 0) continue;
    p.mean_deg = sum / static_cast<double>(p.points);
    a.position_error.push_back(p);
  }

  // 6. Efficiency map at the ME angle.
  for (const auto& c : a.curves) {
    EfficiencyCell cell;
    cell.configuration = c.configuration;
    cell.speed_rpm = c.speed_rpm;
    cell.load_Nm = c.load_Nm;
    cell.angle_deg = c.me.angle_deg;
    cell.pm_W = c.me.pm_W;
    cell.pdcm_W = c.me.pdcm_W;
    cell.efficiency = c.me.efficiency;
    cell.refined = c.me.refined;
    cell.pm_u_W = c.me.pm_u_W;
    cell.pdcm_u_W = c.me.pdcm_u_W;
    cell.efficiency_u = c.me.efficiency_u;
    cell.efficiency_u_repeat = c.me.efficiency_u_repeat;
    a.efficiency.push_back(cell);
  }
  a.efficiency_contours = efficiency_contours(a.efficiency, options.contours);
  return a;
}

}  // namespace synbench::bench
