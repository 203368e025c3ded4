// Golden section on I_m, a stencil around both optima, least-squares parabolic finish.
#include "bench/sweep_plan_angle_search.hpp"

#include <algorithm>
#include <cmath>

#include "bench/analysis_fit.hpp"

namespace synbench::bench {
namespace {

const double kGolden = (std::sqrt(5.0) - 1.0) / 2.0;  // 0.618...

}  // namespace

AngleSearch::AngleSearch(AngleSearchOptions options) : opt_(options) {
  ga_ = opt_.from_deg;
  gb_ = opt_.to_deg;
  x1_ = round(ga_ + (1 - kGolden) * (gb_ - ga_));
  x2_ = round(ga_ + kGolden * (gb_ - ga_));
}

double AngleSearch::round(double angle_deg) const {
  if (opt_.resolution_deg <= 0) return angle_deg;
  return std::round(angle_deg / opt_.resolution_deg) * opt_.resolution_deg;
}

double AngleSearch::clamp(double angle_deg) const {
  return std::clamp(angle_deg, opt_.from_deg, opt_.to_deg);
}

double AngleSearch::distance_to_points(double angle_deg) const {
  double d = INFINITY;
  for (const auto& p : points_) d = std::min(d, std::fabs(p.angle_deg - angle_deg));
  return d;
}

void AngleSearch::report(double angle_deg, double im_A, double pdcm_W, std::optional<double> im_u_A,
                         std::optional<double> pdcm_u_W) {
  points_.push_back({angle_deg, im_A, pdcm_W, im_u_A, pdcm_u_W});
  if (!golden_) return;
  const double same = std::max(opt_.resolution_deg, 1e-9) / 2;
  if (!f1_ && std::fabs(angle_deg - x1_) <= same) {
    f1_ = im_A;
  } else if (!f2_ && std::fabs(angle_deg - x2_) <= same) {
    f2_ = im_A;
  }
  // Golden section keeps the interior point with the smaller current and probes the mirror
  // point of the shrunken bracket.
  // Also stop once rounding to the resolution could no longer shrink the bracket.
  const double golden_stop = std::max(5.0 / 3.0 * opt_.stencil_deg, 4 * opt_.resolution_deg);
  while (golden_ && f1_ && f2_) {
    if (*f1_ <= *f2_) {
      gb_ = x2_;
      x2_ = x1_;
      f2_ = f1_;
      x1_ = round(ga_ + (1 - kGolden) * (gb_ - ga_));
      f1_.reset();
    } else {
      ga_ = x1_;
      x1_ = x2_;
      f1_ = f2_;
      x2_ = round(ga_ + kGolden * (gb_ - ga_));
      f2_.reset();
    }
    if (gb_ - ga_ <= golden_stop) golden_ = false;
    // A probe that lands on a point already measured (after rounding) needs no new measurement.
    for (const auto& p : points_) {
      if (!f1_ && std::fabs(p.angle_deg - x1_) <= same) f1_ = p.im_A;
      if (!f2_ && std::fabs(p.angle_deg - x2_) <= same) f2_ = p.im_A;
    }
  }
}

AngleOptimum AngleSearch::fit_in_window(Objective k, double window_deg) const {
  auto value = [](const AngleSearchEvaluation& p, Objective o) { return o == im ? p.im_A : p.pdcm_W; };
  auto u_of = [](const AngleSearchEvaluation& p, Objective o) { return o == im ? p.im_u_A : p.pdcm_u_W; };
  AngleOptimum out;
  if (points_.empty()) {
    out.angle_deg = round((opt_.from_deg + opt_.to_deg) / 2);
    return out;
  }
  const auto best = std::min_element(points_.begin(), points_.end(), [&](const auto& a, const auto& b) {
    return value(a, k) < value(b, k);
  });
  const double edge = std::max(opt_.resolution_deg, 1e-9);
  auto at_bracket_end = [&](double x) {
    return std::fabs(x - opt_.from_deg) < edge || std::fabs(x - opt_.to_deg) < edge;
  };
  out.angle_deg = best->angle_deg;
  out.im_A = best->im_A;
  out.pdcm_W = best->pdcm_W;
  out.at_edge = at_bracket_end(best->angle_deg);

  // Fit over a window around the best point, then once more around the vertex found: the second
  // pass centres the window on the minimum when the best point sits on one side of it.
  double centre = best->angle_deg;
  std::vector<double> xs, ys, us, other;
  std::optional<QuadraticFit> f;
  bool weighted = false;
  double vertex = centre;
  for (int pass = 0; pass < 2; ++pass) {
    xs.clear();
    ys.clear();
    us.clear();
    other.clear();
    // Only with a target: without one the search keeps its residual-based fits (and proposals).
    weighted = opt_.angle_u_target_deg.has_value();
    for (const auto& p : points_) {
      if (std::fabs(p.angle_deg - centre) > window_deg) continue;
      xs.push_back(p.angle_deg);
      ys.push_back(value(p, k));
      const auto u = u_of(p, k);
      weighted = weighted && u && *u > 0;
      us.push_back(u.value_or(0.0));
      other.push_back(value(p, k == im ? pdcm : im));
    }
    // Points with their u: weighted by them (a lengthened window counts for more), and the
    // vertex's uncertainty from them; else ordinary least squares.
    f = weighted ? fit_quadratic_weighted(xs, ys, us) : fit_quadratic_se(xs, ys);
    if (!f || f->q.c2 <= 0) return out;
    const auto [lo, hi] = std::minmax_element(xs.begin(), xs.end());
    vertex = std::clamp(f->q.vertex(), *lo, *hi);
    centre = vertex;
  }
  out.angle_deg = vertex;
  out.refined = true;
  out.points_used = xs.size();
  if (weighted) {
    out.angle_u_deg = f->vertex_se;
    // The residual-based standard error as well, for the tolerance rule.
    if (const auto plain = fit_quadratic_se(xs, ys)) out.angle_se_deg = plain->vertex_se;
  } else {
    out.angle_se_deg = f->vertex_se;
  }
  out.at_edge = out.at_edge || at_bracket_end(vertex);
  // The other quantity from its own parabola over the same points (three distinct angles at
  // least, or the first fit would have failed).
  const auto q_other = fit_quadratic(xs, other);
  const double v_other = q_other ? (*q_other)(vertex) : value(*best, k == im ? pdcm : im);
  out.im_A = k == im ? f->q(vertex) : v_other;
  out.pdcm_W = k == im ? v_other : f->q(vertex);
  return out;
}

AngleOptimum AngleSearch::fit(Objective k) const {
  // How well a fit fixes its vertex: from the points' u where known, else from its residuals.
  const auto spread = [](const AngleOptimum& o) {
    return o.angle_u_deg ? *o.angle_u_deg : o.angle_se_deg.value_or(INFINITY);
  };
  const AngleOptimum narrow = fit_in_window(k, 1.5 * opt_.stencil_deg);
  // A flat or noisy curve can leave the narrow window's vertex ill determined; a wider window
  // brings in more points (at some bias from the curve's asymmetry), used when it does better.
  if (narrow.refined && spread(narrow) <= opt_.stencil_deg / 3) return narrow;
  const AngleOptimum wide = fit_in_window(k, 2.5 * opt_.stencil_deg);
  if (wide.refined && spread(wide) < spread(narrow)) return wide;
  return narrow;
}

std::optional<double> AngleSearch::next_angle() const {
  if (points_.size() >= opt_.max_evaluations) return std::nullopt;
  if (golden_) {
    if (!f1_) return x1_;
    if (!f2_) return x2_;
  }
  const AngleOptimum mtpa = fit(im), me = fit(pdcm);
  const double lo = std::min(mtpa.angle_deg, me.angle_deg), hi = std::max(mtpa.angle_deg, me.angle_deg);
  const double min_spacing = 2.5 * opt_.tolerance_deg;
  struct Candidate {
    double angle_deg, min_distance;
  };
  std::vector<Candidate> candidates{{round(clamp(lo - opt_.stencil_deg)), min_spacing},
                                    {round(clamp(hi + opt_.stencil_deg)), min_spacing}};
  if (hi - lo < min_spacing) {
    // Both optima close together: one point between them serves both parabolas.
    candidates.push_back({round(clamp((lo + hi) / 2)), opt_.tolerance_deg});
  } else {
    candidates.push_back({round(clamp(mtpa.angle_deg)), opt_.tolerance_deg});
    candidates.push_back({round(clamp(me.angle_deg)), opt_.tolerance_deg});
  }
  // Measure where information is missing most: the candidate farthest from every point so far.
  auto farthest = [&](bool relaxed) {
    std::optional<double> pick;
    double pick_distance = -1;
    for (const auto& c : candidates) {
      const double d = distance_to_points(c.angle_deg);
      const double need = relaxed ? opt_.tolerance_deg : c.min_distance;
      if (d >= need && d > pick_distance) {
        pick = c.angle_deg;
        pick_distance = d;
      }
    }
    return pick;
  };
  // With a target, the stencil is only a means: stop as soon as both angles are known well enough.
  if (opt_.angle_u_target_deg && target_met(mtpa) && target_met(me)) return std::nullopt;
  if (auto pick = farthest(false)) return pick;
  if (opt_.angle_u_target_deg) return toward_target(mtpa, me);

  // The stencil is complete. Stop when both vertices are determined to half the tolerance;
  // otherwise (noise) spend the remaining budget around the optima.
  const double se_inf = INFINITY;
  // An error estimate from a single residual degree of freedom is too rough to stop on.
  auto se_of = [&](const AngleOptimum& o) {
    return o.refined && o.points_used >= 5 ? o.angle_se_deg.value_or(se_inf) : se_inf;
  };
  const double se = std::max(se_of(mtpa), se_of(me));
  if (se <= opt_.tolerance_deg / 2) return std::nullopt;
  if (auto pick = farthest(true)) return pick;
  // Every candidate already measured: split the widest gap of the stencil.
  const double from = round(clamp(lo - opt_.stencil_deg)), to = round(clamp(hi + opt_.stencil_deg));
  std::vector<double> xs{from, to};
  for (const auto& p : points_)
    if (p.angle_deg > from && p.angle_deg < to) xs.push_back(p.angle_deg);
  std::sort(xs.begin(), xs.end());
  double gap = 0, mid = 0;
  for (std::size_t i = 0; i + 1 < xs.size(); ++i) {
    if (xs[i + 1] - xs[i] > gap) {
      gap = xs[i + 1] - xs[i];
      mid = (xs[i] + xs[i + 1]) / 2;
    }
  }
  if (gap < opt_.tolerance_deg) return std::nullopt;
  return round(mid);
}

bool AngleSearch::target_met(const AngleOptimum& o) const {
  // A vertex on the bracket's edge may lie beyond it: its u says nothing about the optimum. Three
  // points in the window fit the parabola exactly, with nothing to show it is one.
  return opt_.angle_u_target_deg && o.refined && !o.at_edge && o.points_used >= 4 && o.angle_u_deg &&
         *o.angle_u_deg <= *opt_.angle_u_target_deg;
}

std::optional<double> AngleSearch::toward_target(const AngleOptimum& mtpa, const AngleOptimum& me) const {
  const bool mtpa_met = target_met(mtpa), me_met = target_met(me);
  if (mtpa_met && me_met) return std::nullopt;
  // A vertex's uncertainty falls most with points far out on both flanks (they fix the slope
  // and the curvature) and some at the vertex: the stencil's ends and the vertex, taking in turn
  // the one with the fewest points within the tolerance (the first in this order on a tie).
  std::vector<double> candidates;
  for (const AngleOptimum* o : {&mtpa, &me}) {
    if (target_met(*o)) continue;
    candidates.push_back(round(clamp(o->angle_deg - opt_.stencil_deg)));
    candidates.push_back(round(clamp(o->angle_deg + opt_.stencil_deg)));
    candidates.push_back(round(clamp(o->angle_deg)));
  }
  std::optional<double> pick;
  std::size_t fewest = 0;
  for (const double c : candidates) {
    std::size_t near = 0;
    for (const auto& p : points_) near += std::fabs(p.angle_deg - c) < opt_.tolerance_deg;
    if (!pick || near < fewest) {
      pick = c;
      fewest = near;
    }
  }
  return pick;
}

AngleSearchResult AngleSearch::result() const {
  AngleSearchResult r{fit(im), fit(pdcm), points_.size(), false};
  r.angle_u_target_met = target_met(r.mtpa) && target_met(r.me);
  return r;
}

}  // namespace synbench::bench
