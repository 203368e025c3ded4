// Uncertainty of the analysis on synthetic records: a known parabola plus seeded normal noise of a
// known standard uncertainty. The Monte Carlo angle u against the scatter of the angle over many
// independently noised curves, against linear propagation through the three-point vertex where
// that is valid; nulls where a point has no u; the significance of ME minus MTPA at a zero and a
// large true difference; the deltas' u from the optima's repeat parts; the efficiency map's u;
// the JSON contract and the CSV columns.
#include "bench/analysis_uncertainty.hpp"

#include <gtest/gtest.h>
#include "drivers/json.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <tuple>

#include "bench/analysis_fit.hpp"
#include "bench/sweep_plan.hpp"

namespace synbench::bench {
namespace {

using drivers::Estimator;
using drivers::Pwm;

constexpr Configuration kEkf{Estimator::ekf_basic, Pwm::aspwm};

// One curve: im_A and pdcm_W parabolic in the angle (minima at mtpa_deg and me_deg), measured on
// the 2-degree grid with normal noise of standard deviation u_im_A and u_pdcm_W, reported as
// the points' repeat parts; the combined u adds a systematic part of sys_frac x the value.
struct Spec {
  Configuration config = kReferenceConfiguration;
  double speed_rpm = 200, load_Nm = 1;
  double mtpa_deg = 51.3, me_deg = 53.1;
  double im_min_A = 2.0, im_curv = 4e-4;   // im = im_min (1 + im_curv (a - mtpa)^2)
  double pdcm_min_W = 60, pdcm_curv = 0.01;  // pdcm = pdcm_min + pdcm_curv (a - me)^2
  double pm_W = 20;
  double u_im_A = 0.002, u_pdcm_W = 0.05, u_pm_W = 0.03;
  double sys_frac = 0.005;
  bool with_u = true;
};

void add_curve(std::vector<PointRecord>& out, const Spec& s, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> z;
  for (double a : inclusive_range(40, 76, 2)) {
    PointRecord r;
    r.speed_rpm = s.speed_rpm;
    r.load_Nm = s.load_Nm;
    r.angle_deg = a;
    r.estimator = s.config.estimator;
    r.pwm = s.config.pwm;
    r.im_A = s.im_min_A * (1 + s.im_curv * (a - s.mtpa_deg) * (a - s.mtpa_deg)) + s.u_im_A * z(rng);
    r.pdcm_W = s.pdcm_min_W + s.pdcm_curv * (a - s.me_deg) * (a - s.me_deg) + s.u_pdcm_W * z(rng);
    r.pm_W = s.pm_W + s.u_pm_W * z(rng);
    r.efficiency = r.pm_W / r.pdcm_W;
    if (s.with_u) {
      const auto combined = [&](double repeat, double value) { return std::hypot(repeat, s.sys_frac * value); };
      r.im_u_repeat_A = s.u_im_A;
      r.im_u_A = combined(s.u_im_A, r.im_A);
      r.pdcm_u_repeat_W = s.u_pdcm_W;
      r.pdcm_u_W = combined(s.u_pdcm_W, r.pdcm_W);
      r.pm_u_W = combined(s.u_pm_W, r.pm_W);
      // What the budget reports for pm / pdcm with independent meters.
      const double eff = r.pm_W / r.pdcm_W;
      r.efficiency_u_repeat = eff * std::hypot(s.u_pm_W / r.pm_W, s.u_pdcm_W / r.pdcm_W);
      r.efficiency_u = combined(*r.efficiency_u_repeat, eff);
    }
    out.push_back(r);
  }
}

Analysis analyze_one(const Spec& s, std::uint64_t seed) {
  std::vector<PointRecord> r;
  add_curve(r, s, seed);
  return analyze(r);
}

double mean(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m += x;
  return m / static_cast<double>(v.size());
}
double sd(const std::vector<double>& v) {
  const double m = mean(v);
  double ss = 0;
  for (double x : v) ss += (x - m) * (x - m);
  return std::sqrt(ss / static_cast<double>(v.size() - 1));
}

// ---------------------------------------------------------------- the angles' u

TEST(AnalysisUncertainty, MonteCarloAngleUAgreesWithTheScatterOverNoisedCurves) {
  // pdcm_W noise u = 0.05 W on a parabola of 0.01 W/deg^2 (0.04 W between neighbours at the
  // minimum: the sample chosen changes often, the nonlinear case) and a steeper one.
  for (const double curv : {0.01, 0.04}) {
    Spec s;
    s.pdcm_curv = curv;
    std::vector<double> angles, us;
    for (std::uint64_t seed = 1; seed <= 300; ++seed) {
      const auto a = analyze_one(s, seed);
      ASSERT_EQ(a.curves.size(), 1u);
      const auto& c = a.curves[0];
      if (!c.me.angle_u_deg) continue;  // an edge minimum under noise
      angles.push_back(c.me.angle_deg);
      us.push_back(*c.me.angle_u_deg);
    }
    ASSERT_GT(angles.size(), 280u) << curv;
    // The scatter of 290-odd angles is known to about 4 % (1 / sqrt(2 n)); the reported u is
    // evaluated around each noised curve, not the truth: within 20 % of each other.
    const double scatter = sd(angles), reported = mean(us);
    EXPECT_GT(scatter, 0.1) << curv;  // not a degenerate case
    EXPECT_NEAR(reported / scatter, 1.0, 0.20) << "curvature " << curv << ": scatter " << scatter << " reported "
                                                 << reported;
  }
}

TEST(AnalysisUncertainty, MonteCarloAgreesWithLinearPropagationThroughTheVertexWhereThatIsValid) {
  // Noise far below the step between neighbours: the smallest sample never changes and the
  // vertex is nearly linear in the three samples, so u = sqrt(sum (d vertex / d y_k)^2 u^2).
  Spec s;
  s.pdcm_curv = 0.05;
  s.u_pdcm_W = 0.004;
  s.u_im_A = 1e-4;
  std::vector<PointRecord> recs;
  add_curve(recs, s, 7);
  const auto a = analyze(recs);
  const auto& c = a.curves[0];
  ASSERT_TRUE(c.me.refined);
  ASSERT_TRUE(c.me.angle_u_deg);
  std::vector<double> x, y;
  for (const auto& r : recs) {
    x.push_back(r.angle_deg);
    y.push_back(r.pdcm_W);
  }
  const auto m = refine_minimum(x, y);
  double var = 0;
  for (std::size_t k = m.index - 1; k <= m.index + 1; ++k) {
    auto yp = y, ym = y;
    const double h = 1e-6;
    yp[k] += h;
    ym[k] -= h;
    const double g = (refine_minimum(x, yp).x - refine_minimum(x, ym).x) / (2 * h);
    var += g * g * s.u_pdcm_W * s.u_pdcm_W;
  }
  const double linear = std::sqrt(var);
  // 400 draws: the SD within about 3.5 % (1 sigma) of its limit.
  EXPECT_NEAR(*c.me.angle_u_deg / linear, 1.0, 0.12) << "MC " << *c.me.angle_u_deg << " linear " << linear;
  // The value at the optimum: first order, the vertex does not move pdcm (slope zero there), so
  // its repeat u is the parabola's own through the three samples: well below the point's u.
  ASSERT_TRUE(c.me.pdcm_u_repeat_W);
  EXPECT_LT(*c.me.pdcm_u_repeat_W, s.u_pdcm_W);
  EXPECT_GT(*c.me.pdcm_u_repeat_W, 0.3 * s.u_pdcm_W);
  // The absolute value adds the points' systematic part (0.5 % of 60 W = 0.3 W).
  ASSERT_TRUE(c.me.pdcm_u_W);
  EXPECT_NEAR(*c.me.pdcm_u_W, std::hypot(*c.me.pdcm_u_repeat_W, 0.005 * c.me.pdcm_W), 0.002);
}

TEST(AnalysisUncertainty, ResultsRepeatWithTheSeedAndDoNotDependOnOtherCurves) {
  Spec s;
  std::vector<PointRecord> one;
  add_curve(one, s, 3);
  std::vector<PointRecord> two = one;
  Spec other = s;
  other.speed_rpm = 300;
  add_curve(two, other, 4);
  const auto a = analyze(one), b = analyze(one), c = analyze(two);
  ASSERT_TRUE(a.curves[0].me.angle_u_deg);
  EXPECT_EQ(*a.curves[0].me.angle_u_deg, *b.curves[0].me.angle_u_deg);
  EXPECT_EQ(*a.curves[0].me.angle_u_deg, *c.curves[0].me.angle_u_deg);
  EXPECT_EQ(*a.curves[0].me_minus_mtpa_u_deg, *c.curves[0].me_minus_mtpa_u_deg);
  AnalysisOptions o;
  o.uncertainty_seed = 99;
  const auto d = analyze(one, o);
  EXPECT_NE(*a.curves[0].me.angle_u_deg, *d.curves[0].me.angle_u_deg);
  // ... but agrees within the Monte Carlo's own scatter (about 3.5 % at 400 draws).
  EXPECT_NEAR(*d.curves[0].me.angle_u_deg / *a.curves[0].me.angle_u_deg, 1.0, 0.15);
}

// ---------------------------------------------------------------- nulls

TEST(AnalysisUncertainty, NullsPropagateAndNothingIsInvented) {
  Spec s;
  s.with_u = false;
  const auto a = analyze_one(s, 1);
  const auto& c = a.curves[0];
  for (const auto* o : {&c.mtpa, &c.me}) {
    EXPECT_FALSE(o->angle_u_deg);
    EXPECT_FALSE(o->im_u_A);
    EXPECT_FALSE(o->pdcm_u_W);
    EXPECT_FALSE(o->pm_u_W);
    EXPECT_FALSE(o->efficiency_u);
    EXPECT_FALSE(o->efficiency_u_repeat);
  }
  EXPECT_FALSE(c.me_minus_mtpa_u_deg);
  EXPECT_FALSE(c.me_minus_mtpa_significant);
  EXPECT_FALSE(a.efficiency[0].efficiency_u);
  const auto j = to_json(a);
  const auto& e = j["curves"]["entries"][0];
  EXPECT_TRUE(e["mtpa_angle_u_deg"].is_null());
  EXPECT_TRUE(e["me_minus_mtpa_significant"].is_null());
  EXPECT_TRUE(e["me"]["efficiency_u"].is_null());
  EXPECT_EQ(j["uncertainty"]["me_minus_mtpa"]["known"], 0);
  EXPECT_EQ(j["uncertainty"]["efficiency_map"]["known"], 0);

  // One point without pdcm's repeat u: the ME angle and everything read through pdcm is
  // unknown; the MTPA angle and im there stay known.
  std::vector<PointRecord> r;
  s.with_u = true;
  add_curve(r, s, 1);
  r[9].pdcm_u_repeat_W.reset();
  const auto b = analyze(r);
  const auto& d = b.curves[0];
  EXPECT_TRUE(d.mtpa.angle_u_deg);
  EXPECT_TRUE(d.mtpa.im_u_A);
  EXPECT_FALSE(d.mtpa.pdcm_u_W);
  EXPECT_FALSE(d.me.angle_u_deg);
  EXPECT_FALSE(d.me.im_u_A);  // read at an angle whose u is unknown
  EXPECT_FALSE(d.me.efficiency_u);
  EXPECT_FALSE(d.me_minus_mtpa_u_deg);
  EXPECT_FALSE(d.me_minus_mtpa_significant);

  // Only the combined u missing: the repeat parts (and the angles) known, the absolute ones not.
  r.clear();
  add_curve(r, s, 1);
  r[3].im_u_A.reset();
  const auto e2 = analyze(r).curves[0];
  EXPECT_TRUE(e2.mtpa.angle_u_deg);
  EXPECT_TRUE(e2.mtpa.im_u_repeat_A);
  EXPECT_FALSE(e2.mtpa.im_u_A);
  EXPECT_TRUE(e2.mtpa.pdcm_u_W);
}

TEST(AnalysisUncertainty, AnEdgeMinimumHasNoAngleUncertainty) {
  Spec s;
  s.me_deg = 30;  // pdcm falls over the whole range: the minimum at 76 deg is an edge
  const auto c = analyze_one(s, 2).curves[0];
  EXPECT_TRUE(c.me.at_edge);
  EXPECT_FALSE(c.me.angle_u_deg);
  EXPECT_TRUE(c.mtpa.angle_u_deg);
  EXPECT_FALSE(c.me_minus_mtpa_u_deg);
  EXPECT_FALSE(c.me_minus_mtpa_significant);
}

// ---------------------------------------------------------------- significance

TEST(AnalysisUncertainty, MeMinusMtpaSignificanceHoldsItsLevel) {
  // Zero true difference: both minima at 52.4 deg; the 95 % interval should miss 0 in about
  // 5 % of the noised curves (300 seeds: 95 +/- 1.3 %; the band allows the Monte Carlo's own
  // approximation).
  Spec zero;
  zero.mtpa_deg = zero.me_deg = 52.4;
  zero.im_curv = 4e-4;
  zero.u_im_A = 0.002;  // the MTPA angle's u is then comparable to the ME angle's
  std::size_t known = 0, not_significant = 0;
  for (std::uint64_t seed = 1; seed <= 300; ++seed) {
    const auto c = analyze_one(zero, 1000 + seed).curves[0];
    if (!c.me_minus_mtpa_significant) continue;
    ++known;
    if (!*c.me_minus_mtpa_significant) ++not_significant;
  }
  ASSERT_GT(known, 280u);
  const double rate = static_cast<double>(not_significant) / static_cast<double>(known);
  EXPECT_GT(rate, 0.90) << not_significant << " of " << known;
  EXPECT_LT(rate, 0.995) << not_significant << " of " << known;

  // A large one (8 deg) is significant on every seed.
  Spec large = zero;
  large.me_deg = 60.4;
  for (std::uint64_t seed = 1; seed <= 50; ++seed) {
    const auto c = analyze_one(large, 2000 + seed).curves[0];
    ASSERT_TRUE(c.me_minus_mtpa_significant);
    EXPECT_TRUE(*c.me_minus_mtpa_significant) << seed;
    EXPECT_NEAR(c.me_minus_mtpa_deg, 8.0, 5 * *c.me_minus_mtpa_u_deg);
  }
}

// ---------------------------------------------------------------- deltas

TEST(AnalysisUncertainty, DeltaUCombinesTheOptimaRepeatPartsInQuadrature) {
  std::vector<PointRecord> r;
  Spec ref;
  add_curve(r, ref, 11);
  Spec ekf = ref;
  ekf.config = kEkf;
  ekf.pdcm_min_W = 57;  // 3 W less: significant
  ekf.me_deg = 53.3;    // 0.2 deg: not, with these u
  add_curve(r, ekf, 12);
  const auto a = analyze(r);
  ASSERT_EQ(a.deltas.size(), 1u);
  const auto& d = a.deltas[0];
  const auto& cr = a.curves[0];
  const auto& ce = a.curves[1];
  ASSERT_EQ(ce.configuration, kEkf);
  for (const auto& [t, x, y] : {std::tuple{&d.mtpa, &ce.mtpa, &cr.mtpa}, std::tuple{&d.me, &ce.me, &cr.me}}) {
    ASSERT_TRUE(t->delta_angle_u_deg && t->delta_im_u_A && t->delta_pdcm_u_W);
    EXPECT_DOUBLE_EQ(*t->delta_angle_u_deg, std::hypot(*x->angle_u_deg, *y->angle_u_deg));
    EXPECT_DOUBLE_EQ(*t->delta_im_u_A, std::hypot(*x->im_u_repeat_A, *y->im_u_repeat_A));
    EXPECT_DOUBLE_EQ(*t->delta_pdcm_u_W, std::hypot(*x->pdcm_u_repeat_W, *y->pdcm_u_repeat_W));
    // The systematic parts cancel: the delta's u is below the optima's absolute ones.
    EXPECT_LT(*t->delta_pdcm_u_W, std::hypot(*x->pdcm_u_W, *y->pdcm_u_W));
    EXPECT_EQ(*t->delta_angle_significant, std::fabs(t->delta_angle_deg) > 1.96 * *t->delta_angle_u_deg);
    EXPECT_EQ(*t->delta_im_significant, std::fabs(t->delta_im_A) > 1.96 * *t->delta_im_u_A);
  }
  EXPECT_TRUE(*d.me.delta_pdcm_significant);
  EXPECT_FALSE(*d.me.delta_angle_significant);
  // The summary counts them.
  const auto j = to_json(a);
  const auto& u = j["uncertainty"]["deltas"];
  EXPECT_EQ(u["entries"], 1);
  EXPECT_EQ(u["me"]["delta_pdcm_W"]["known"], 1);
  EXPECT_EQ(u["me"]["delta_pdcm_W"]["significant"], 1);
  EXPECT_EQ(u["me"]["delta_angle_deg"]["significant"], 0);
  const auto& jd = j["deltas"]["entries"][0]["me"];
  EXPECT_DOUBLE_EQ(jd["delta_pdcm_u_W"].get<double>(), *d.me.delta_pdcm_u_W);
  EXPECT_EQ(jd["delta_pdcm_significant"], true);

  // Without the reference's u the deltas' u are unknown, never a one-sided number.
  for (std::size_t i = 0; i < 19; ++i) r[i].pdcm_u_repeat_W.reset();
  const auto b = analyze(r);
  EXPECT_FALSE(b.deltas[0].me.delta_pdcm_u_W);
  EXPECT_FALSE(b.deltas[0].me.delta_pdcm_significant);
  EXPECT_TRUE(b.deltas[0].mtpa.delta_im_u_A);
}

// ---------------------------------------------------------------- efficiency map, JSON, CSV

TEST(AnalysisUncertainty, EfficiencyMapCellsCarryTheirUncertainty) {
  std::vector<PointRecord> r;
  std::uint64_t seed = 20;
  for (double speed : {100.0, 200.0})
    for (double load : {0.5, 1.0}) {
      Spec s;
      s.speed_rpm = speed;
      s.load_Nm = load;
      s.pm_W = speed * load * 0.1;
      add_curve(r, s, ++seed);
    }
  const auto a = analyze(r);
  ASSERT_EQ(a.efficiency.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    const auto& cell = a.efficiency[i];
    const auto& me = a.curves[i].me;
    ASSERT_TRUE(cell.efficiency_u && cell.efficiency_u_repeat && cell.pm_u_W && cell.pdcm_u_W);
    EXPECT_EQ(*cell.efficiency_u, *me.efficiency_u);
    EXPECT_GE(*cell.efficiency_u, *cell.efficiency_u_repeat);
    // Order of magnitude: the point's own efficiency u at the optimum's sample.
    const double eff = cell.efficiency;
    const double point_rep = eff * std::hypot(0.03 / cell.pm_W, 0.05 / cell.pdcm_W);
    EXPECT_GT(*cell.efficiency_u_repeat, 0.3 * point_rep);
    EXPECT_LT(*cell.efficiency_u_repeat, 1.5 * point_rep);
  }
  const auto j = to_json(a);
  const auto& m = j["efficiency_map"]["entries"][0];
  ASSERT_EQ(m["efficiency_u"].size(), 2u);  // rows = speeds
  ASSERT_EQ(m["efficiency_u"][0].size(), 2u);
  EXPECT_DOUBLE_EQ(m["efficiency_u"][1][0].get<double>(), *a.efficiency[2].efficiency_u);  // 200 rpm, 0.5 Nm
  EXPECT_DOUBLE_EQ(m["efficiency_u_repeat"][0][1].get<double>(), *a.efficiency[1].efficiency_u_repeat);
  EXPECT_DOUBLE_EQ(m["cells"][3]["efficiency_u"].get<double>(), *a.efficiency[3].efficiency_u);
  EXPECT_EQ(j["uncertainty"]["efficiency_map"]["known"], 4);
}

TEST(AnalysisUncertainty, JsonContractAndCsvColumns) {
  std::vector<PointRecord> r;
  add_curve(r, Spec{}, 5);
  const auto a = analyze(r);
  const auto j = to_json(a);
  const auto& e = j["curves"]["entries"][0];
  for (const char* k : {"mtpa_angle_u_deg", "me_angle_u_deg", "me_minus_mtpa_deg", "me_minus_mtpa_u_deg"})
    EXPECT_TRUE(e[k].is_number()) << k;
  EXPECT_TRUE(e["me_minus_mtpa_significant"].is_boolean());
  EXPECT_DOUBLE_EQ(e["me_angle_u_deg"].get<double>(), *a.curves[0].me.angle_u_deg);
  for (const char* o : {"mtpa", "me"})
    for (const char* k : {"im_u_A", "pdcm_u_W", "efficiency_u", "im_u_repeat_A", "pdcm_u_repeat_W", "pm_u_W",
                          "efficiency_u_repeat"})
      EXPECT_TRUE(e[o][k].is_number()) << o << "." << k;
  const auto& u = j["uncertainty"];
  EXPECT_TRUE(u["description"].is_string());
  EXPECT_EQ(u["method"]["draws"], 400);
  EXPECT_EQ(u["me_minus_mtpa"]["curves"], 1);
  EXPECT_EQ(u["me_minus_mtpa"]["known"], 1);

  const std::string csv = analysis_curves_csv(a);
  const auto header = csv.substr(0, csv.find('\n'));
  const auto row = csv.substr(header.size() + 1, csv.find('\n', header.size() + 1) - header.size() - 1);
  const auto column = [&](const std::string& name) {
    std::size_t idx = 0, pos = 0;
    const std::string h = "," + header + ",";
    const auto at = h.find("," + name + ",");
    EXPECT_NE(at, std::string::npos) << name;
    for (std::size_t i = 0; i < at; ++i) idx += h[i] == ',' ? 1 : 0;
    for (std::size_t i = 0; i < idx; ++i) pos = row.find(',', pos) + 1;
    return row.substr(pos, row.find(',', pos) - pos);
  };
  EXPECT_NEAR(std::stod(column("me_angle_u_deg")), *a.curves[0].me.angle_u_deg, 1e-8);
  EXPECT_NEAR(std::stod(column("me_minus_mtpa_u_deg")), *a.curves[0].me_minus_mtpa_u_deg, 1e-8);
  EXPECT_EQ(column("me_minus_mtpa_significant"), *a.curves[0].me_minus_mtpa_significant ? "1" : "0");
  EXPECT_EQ(column("me_delta_pdcm_u_W"), "");  // the reference has no delta
  // Every row has as many cells as the header.
  EXPECT_EQ(std::count(header.begin(), header.end(), ','), std::count(row.begin(), row.end(), ','));
}

TEST(AnalysisUncertainty, AThesisGridSizedAnalysisStaysFast) {
  // About 280 curves of 19 angles (the thesis grid): the draws must stay a small cost. Not a
  // timing assertion on a shared machine; a generous bound catches a runaway draw count.
  std::vector<PointRecord> r;
  std::uint64_t seed = 0;
  for (const auto& config : {kReferenceConfiguration, kEkf})
    for (double speed : inclusive_range(100, 1400, 100))
      for (double load : inclusive_range(0.5, 5, 0.5)) {
        Spec s;
        s.config = config;
        s.speed_rpm = speed;
        s.load_Nm = load;
        add_curve(r, s, ++seed);
      }
  const auto t0 = std::chrono::steady_clock::now();
  const auto a = analyze(r);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(a.curves.size(), 280u);
  EXPECT_LT(s, 5.0);
  std::printf("thesis-grid-sized analysis: %zu curves in %.3f s\n", a.curves.size(), s);
}

}  // namespace
}  // namespace synbench::bench
