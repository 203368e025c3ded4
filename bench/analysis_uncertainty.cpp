// Monte Carlo propagation to a curve's optima, and the deltas' uncertainties.
#include "bench/analysis_uncertainty.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "bench/analysis_fit.hpp"

namespace synbench::bench {
namespace {

double ratio(double num, double den) { return den > 0 ? num / den : 0.0; }

// Sample standard deviation of v (n - 1).
double sd(const std::vector<double>& v) {
  if (v.size() < 2) return 0;
  double mean = 0;
  for (double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  double ss = 0;
  for (double x : v) ss += (x - mean) * (x - mean);
  return std::sqrt(ss / static_cast<double>(v.size() - 1));
}

// The p-quantile of sorted values, interpolated between order statistics.
double quantile(const std::vector<double>& sorted, double p) {
  const double h = p * static_cast<double>(sorted.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(h));
  const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
  return sorted[lo] + (h - static_cast<double>(lo)) * (sorted[hi] - sorted[lo]);
}

double hypot0(double a, double b) { return std::sqrt(a * a + b * b); }

std::optional<double> when(bool known, double v) { return known ? std::optional<double>(v) : std::nullopt; }

// Every draw's values at one optimum.
struct Drawn {
  std::vector<double> angle, im, pdcm, pm, efficiency;
  void reserve(std::size_t n) {
    for (auto* v : {&angle, &im, &pdcm, &pm, &efficiency}) v->reserve(n);
  }
  void add(const CurveOptimum& o) {
    angle.push_back(o.angle_deg);
    im.push_back(o.im_A);
    pdcm.push_back(o.pdcm_W);
    pm.push_back(o.pm_W);
    efficiency.push_back(o.efficiency);
  }
};

// The systematic part at an optimum: the smallest sample's (the parts vary slowly along a curve,
// and the optimum lies within a grid step of it).
double systematic_at(const SampleUncertainty& u, const CurveSamples& s, const CurveOptimum& o) {
  std::size_t i = 0;
  for (std::size_t k = 1; k < s.angle_deg.size(); ++k)
    if (std::fabs(s.angle_deg[k] - o.angle_deg) < std::fabs(s.angle_deg[i] - o.angle_deg)) i = k;
  return u.systematic[i];
}

void fill_optimum(CurveOptimum& o, const Drawn& d, const CurveSamples& s, bool angle_known, bool by_current) {
  const bool im = s.im.known_repeat(), pdcm = s.pdcm.known_repeat(), pm = s.pm.known_repeat();
  // What moves the angle: the quantity minimised.
  const bool angle = by_current ? im : pdcm;
  o.angle_u_deg = when(angle && angle_known, sd(d.angle));
  o.im_u_repeat_A = when(angle && im, sd(d.im));
  o.pdcm_u_repeat_W = when(angle && pdcm, sd(d.pdcm));
  o.efficiency_u_repeat = when(angle && pdcm && pm && o.pdcm_W > 0, sd(d.efficiency));
  const auto absolute = [&](const std::optional<double>& repeat, const SampleUncertainty& u) {
    return repeat && u.known() ? std::optional<double>(hypot0(*repeat, systematic_at(u, s, o))) : std::nullopt;
  };
  o.im_u_A = absolute(o.im_u_repeat_A, s.im);
  o.pdcm_u_W = absolute(o.pdcm_u_repeat_W, s.pdcm);
  o.pm_u_W = absolute(when(angle && pm, sd(d.pm)), s.pm);
  o.efficiency_u = absolute(o.efficiency_u_repeat, s.efficiency);
}

}  // namespace

CurveOptimum curve_optimum(std::span<const double> x, std::span<const double> im, std::span<const double> pdcm,
                           std::span<const double> pm, bool by_current) {
  const auto m = refine_minimum(x, by_current ? im : pdcm);
  CurveOptimum o;
  o.angle_deg = m.x;
  o.refined = m.refined;
  o.at_edge = m.at_edge;
  // Read the other quantities at the refined angle through the same three samples.
  o.im_A = by_current ? m.y : (m.refined ? interpolate_at(x, im, m.index, m.x) : im[m.index]);
  o.pdcm_W = by_current ? (m.refined ? interpolate_at(x, pdcm, m.index, m.x) : pdcm[m.index]) : m.y;
  o.pm_W = m.refined ? interpolate_at(x, pm, m.index, m.x) : pm[m.index];
  o.efficiency = ratio(o.pm_W, o.pdcm_W);
  return o;
}

void propagate_curve_uncertainty(CurveResult& c, const CurveSamples& s, const MonteCarloOptions& options) {
  const std::size_t n = s.angle_deg.size();
  const bool im = s.im.known_repeat(), pdcm = s.pdcm.known_repeat();
  if (n == 0 || options.draws < 2 || !(im || pdcm)) return;
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> z;
  std::vector<double> im_d(s.im_A), pdcm_d(s.pdcm_W), pm_d(s.pm_W);
  // Only samples that can become the smallest (within 6 u of the smallest's reach: a draw beyond
  // that has a probability below 1e-9) and their neighbours enter an optimum; the others are
  // left as measured, which keeps the thesis grid's 280 curves far below a second.
  std::size_t lo = n, hi = 0;
  const auto reach = [&](const std::vector<double>& value, const SampleUncertainty& u) {
    const auto r = [&](std::size_t k) { return u.known_repeat() ? 6 * u.repeat[k] : 0.0; };
    double best = value[0] + r(0);
    for (std::size_t k = 1; k < n; ++k) best = std::min(best, value[k] + r(k));
    for (std::size_t k = 0; k < n; ++k)
      if (value[k] - r(k) <= best) {
        lo = std::min(lo, k == 0 ? 0 : k - 1);
        hi = std::max(hi, std::min(n - 1, k + 1));
      }
  };
  reach(s.im_A, s.im);
  reach(s.pdcm_W, s.pdcm);
  const auto draw = [&](std::vector<double>& out, const std::vector<double>& value, const SampleUncertainty& u) {
    if (!u.known_repeat()) return;  // drawn as measured; whatever depends on it is left empty
    for (std::size_t k = lo; k <= hi; ++k) out[k] = value[k] + u.repeat[k] * z(rng);
  };
  Drawn mtpa, me;
  mtpa.reserve(options.draws);
  me.reserve(options.draws);
  std::vector<double> difference;
  difference.reserve(options.draws);
  for (std::size_t i = 0; i < options.draws; ++i) {
    draw(im_d, s.im_A, s.im);
    draw(pdcm_d, s.pdcm_W, s.pdcm);
    draw(pm_d, s.pm_W, s.pm);
    const auto a = curve_optimum(s.angle_deg, im_d, pdcm_d, pm_d, true);
    const auto b = curve_optimum(s.angle_deg, im_d, pdcm_d, pm_d, false);
    mtpa.add(a);
    me.add(b);
    difference.push_back(b.angle_deg - a.angle_deg);
  }
  fill_optimum(c.mtpa, mtpa, s, c.mtpa.refined, true);
  fill_optimum(c.me, me, s, c.me.refined, false);
  if (c.mtpa.angle_u_deg && c.me.angle_u_deg) {
    c.me_minus_mtpa_u_deg = sd(difference);
    std::sort(difference.begin(), difference.end());
    const double low = quantile(difference, 0.025), high = quantile(difference, 0.975);
    c.me_minus_mtpa_significant = low > 0 || high < 0;
  }
}

void add_delta_uncertainty(TrajectoryDelta& d, const CurveOptimum& x, const CurveOptimum& reference) {
  const auto combine = [](const std::optional<double>& a, const std::optional<double>& b) {
    return a && b ? std::optional<double>(hypot0(*a, *b)) : std::nullopt;
  };
  const auto significant = [](double delta, const std::optional<double>& u) {
    return u ? std::optional<bool>(std::fabs(delta) > 1.96 * *u) : std::nullopt;
  };
  d.delta_angle_u_deg = combine(x.angle_u_deg, reference.angle_u_deg);
  d.delta_im_u_A = combine(x.im_u_repeat_A, reference.im_u_repeat_A);
  d.delta_pdcm_u_W = combine(x.pdcm_u_repeat_W, reference.pdcm_u_repeat_W);
  d.delta_angle_significant = significant(d.delta_angle_deg, d.delta_angle_u_deg);
  d.delta_im_significant = significant(d.delta_im_A, d.delta_im_u_A);
  d.delta_pdcm_significant = significant(d.delta_pdcm_W, d.delta_pdcm_u_W);
}

}  // namespace synbench::bench
