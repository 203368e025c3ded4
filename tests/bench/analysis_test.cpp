// Analysis of stored points on synthetic records whose answers are known in closed form:
// parabola refinement (exact on parabolas, edges flagged), optima with both quantities, deltas
// against the reference, histogram bin edges and counts, position error per load, efficiency map,
// exclusion of flagged points, and the JSON shape the REST API serves.
#include "bench/analysis.hpp"

#include <gtest/gtest.h>
#include "drivers/json.hpp"

#include <cmath>

#include "bench/analysis_fit.hpp"
#include "bench/sweep_plan.hpp"

namespace synbench::bench {
namespace {

using drivers::Estimator;
using drivers::Pwm;

// ---------------------------------------------------------------- fitting helpers

TEST(AnalysisFit, ParabolaRefinementIsExactOnAParabola) {
  std::vector<double> x, y;
  for (double a : inclusive_range(40, 76, 2)) {
    x.push_back(a);
    y.push_back(2.0 + 0.01 * (a - 51.3) * (a - 51.3));
  }
  const auto m = refine_minimum(x, y);
  EXPECT_TRUE(m.refined);
  EXPECT_FALSE(m.at_edge);
  EXPECT_EQ(x[m.index], 52.0);
  EXPECT_NEAR(m.x, 51.3, 1e-9);
  EXPECT_NEAR(m.y, 2.0, 1e-12);
  // Uneven spacing (adaptive points) too.
  const std::vector<double> xu{44, 47, 53, 60};
  std::vector<double> yu;
  for (double a : xu) yu.push_back(5 - 0.2 * a + 0.002 * a * a);  // vertex at 50
  const auto mu = refine_minimum(xu, yu);
  EXPECT_NEAR(mu.x, 50.0, 1e-9);
  EXPECT_NEAR(mu.y, 5 - 0.2 * 50 + 0.002 * 2500, 1e-12);
}

TEST(AnalysisFit, EdgeMinimaAreNotRefinedButFlagged) {
  const std::vector<double> x{40, 42, 44, 46};
  const auto low = refine_minimum(x, std::vector<double>{1.0, 1.1, 1.3, 1.6});
  EXPECT_TRUE(low.at_edge);
  EXPECT_FALSE(low.refined);
  EXPECT_EQ(low.x, 40.0);
  EXPECT_EQ(low.y, 1.0);
  const auto high = refine_minimum(x, std::vector<double>{1.6, 1.3, 1.1, 1.0});
  EXPECT_TRUE(high.at_edge);
  EXPECT_EQ(high.index, 3u);
  // Two points: nothing to refine, and flagged (either could be an edge).
  EXPECT_FALSE(refine_minimum(std::vector<double>{50, 52}, std::vector<double>{1, 2}).refined);
}

TEST(AnalysisFit, InterpolationAndLeastSquares) {
  const std::vector<double> x{40, 42, 44, 46, 48};
  std::vector<double> y;
  for (double a : x) y.push_back(3 + 0.5 * (a - 43) + 0.25 * (a - 43) * (a - 43));
  EXPECT_NEAR(interpolate_at(x, y, 2, 43.7), 3 + 0.5 * 0.7 + 0.25 * 0.49, 1e-12);
  EXPECT_NEAR(interpolate_at(x, y, 0, 41), 3 - 1 + 1, 1e-12);  // index clamped to 1
  const auto q = fit_quadratic(x, y);
  ASSERT_TRUE(q);
  EXPECT_NEAR(q->c2, 0.25, 1e-12);
  EXPECT_NEAR(q->vertex(), 42.0, 1e-9);
  EXPECT_FALSE(fit_quadratic(std::vector<double>{1, 1, 2}, std::vector<double>{1, 2, 3}));
  // Vertex standard error: zero on exact data, unknown with three points, and proportional to
  // the residuals.
  EXPECT_NEAR(fit_quadratic_se(x, y)->vertex_se.value(), 0.0, 1e-6);
  EXPECT_FALSE(fit_quadratic_se(std::vector<double>{1, 2, 3}, std::vector<double>{1, 0, 1})->vertex_se);
  const std::vector<double> e{0.01, -0.02, 0.015, 0.005, -0.01};
  std::vector<double> y1 = y, y2 = y;
  for (std::size_t i = 0; i < y.size(); ++i) {
    y1[i] += e[i];
    y2[i] += 2 * e[i];
  }
  const double se1 = fit_quadratic_se(x, y1)->vertex_se.value(), se2 = fit_quadratic_se(x, y2)->vertex_se.value();
  EXPECT_GT(se1, 0.0);
  EXPECT_NEAR(se2 / se1, 2.0, 0.05);
}

// The vertex's standard error against the textbook computation done independently: normal
// equations in raw x, their inverse by cofactors, the delta method on x* = -a1 / (2 a2).
TEST(AnalysisFit, VertexStandardErrorMatchesTheDeltaMethod) {
  const std::vector<double> x{44, 46, 48, 50, 52, 54, 56};
  const std::vector<double> y{0.912, 0.921, 0.927, 0.929, 0.928, 0.922, 0.915};
  double s[5] = {}, t[3] = {};
  for (std::size_t i = 0; i < x.size(); ++i) {
    for (int k = 0; k < 5; ++k) s[k] += std::pow(x[i], k);
    for (int k = 0; k < 3; ++k) t[k] += std::pow(x[i], k) * y[i];
  }
  const double m[3][3] = {{s[0], s[1], s[2]}, {s[1], s[2], s[3]}, {s[2], s[3], s[4]}};
  const auto cof = [&](int r, int c) {
    const int r0 = (r + 1) % 3, r1 = (r + 2) % 3, c0 = (c + 1) % 3, c1 = (c + 2) % 3;
    return m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0];
  };
  const double det = m[0][0] * cof(0, 0) + m[0][1] * cof(0, 1) + m[0][2] * cof(0, 2);
  double inv[3][3], a[3] = {};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) inv[r][c] = cof(c, r) / det;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) a[r] += inv[r][c] * t[c];
  double rss = 0;
  for (std::size_t i = 0; i < x.size(); ++i) rss += std::pow(y[i] - (a[0] + a[1] * x[i] + a[2] * x[i] * x[i]), 2);
  const double s2 = rss / static_cast<double>(x.size() - 3);
  const double g[3] = {0, -1 / (2 * a[2]), a[1] / (2 * a[2] * a[2])};
  double var = 0;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) var += g[r] * inv[r][c] * g[c];
  // The data open downward (an efficiency maximum): fit the negated values, whose vertex and
  // standard error are the same.
  std::vector<double> neg;
  for (double v : y) neg.push_back(-v);
  const auto fit = fit_quadratic_se(x, neg);
  ASSERT_TRUE(fit && fit->vertex_se);
  EXPECT_NEAR(fit->q.vertex(), -a[1] / (2 * a[2]), 1e-6);
  EXPECT_NEAR(*fit->vertex_se, std::sqrt(s2 * var), 1e-6 * std::sqrt(s2 * var) + 1e-9);
  EXPECT_GT(*fit->vertex_se, 0.05);  // the data are noisy enough for a visible error
}

TEST(AnalysisFit, HistogramBinsAreAlignedToMultiplesOfTheWidth) {
  const auto bins = histogram_bins({-0.75, -0.5, -0.25, 0.0, 0.49, 0.5, 1.6}, 0.5);
  ASSERT_EQ(bins.size(), 6u);
  const std::vector<std::size_t> counts{1, 2, 2, 1, 0, 1};
  for (std::size_t i = 0; i < bins.size(); ++i) {
    EXPECT_DOUBLE_EQ(bins[i].from, -1.0 + 0.5 * static_cast<double>(i)) << i;
    EXPECT_DOUBLE_EQ(bins[i].to, -0.5 + 0.5 * static_cast<double>(i)) << i;
    EXPECT_EQ(bins[i].count, counts[i]) << i;
  }
  // A value meant to be on an edge but computed a hair below it stays in the edge's bin.
  const auto edge = histogram_bins({std::nextafter(1.5, 0.0)}, 0.5);
  ASSERT_EQ(edge.size(), 1u);
  EXPECT_DOUBLE_EQ(edge[0].from, 1.5);
  const auto rs = histogram_bins({-25, -20, 5, 19.99, 20, 45}, 20);
  ASSERT_EQ(rs.size(), 5u);
  EXPECT_DOUBLE_EQ(rs[0].from, -40.0);
  EXPECT_EQ(rs[0].count, 1u);
  EXPECT_EQ(rs[1].count, 1u);  // -20 starts [-20, 0)
  EXPECT_EQ(rs[2].count, 2u);
  EXPECT_EQ(rs[3].count, 1u);
  EXPECT_EQ(rs[4].count, 1u);
  EXPECT_DOUBLE_EQ(rs[4].to, 60.0);
  EXPECT_TRUE(histogram_bins({}, 0.5).empty());
}

// ---------------------------------------------------------------- analysis of synthetic records

// A curve with I_m and P_dcM parabolic in the angle, minima at known angles.
struct CurveSpec {
  Configuration config;
  double speed_rpm, load_Nm;
  double mtpa_deg, im_min_A;
  double me_deg, pdcm_min_W;
  double pm_W;
};

double im_of(const CurveSpec& c, double a) { return c.im_min_A * (1 + 4e-4 * (a - c.mtpa_deg) * (a - c.mtpa_deg)); }
double pdcm_of(const CurveSpec& c, double a) { return c.pdcm_min_W + 0.08 * (a - c.me_deg) * (a - c.me_deg); }

void add_curve(std::vector<PointRecord>& out, const CurveSpec& c) {
  for (double a : inclusive_range(40, 76, 2)) {
    PointRecord r;
    r.speed_rpm = c.speed_rpm;
    r.load_Nm = c.load_Nm;
    r.angle_deg = a;
    r.estimator = c.config.estimator;
    r.pwm = c.config.pwm;
    r.im_A = im_of(c, a);
    r.pdcm_W = pdcm_of(c, a);
    r.pm_W = c.pm_W;
    r.efficiency = r.pm_W / r.pdcm_W;
    if (c.config.estimator != Estimator::encoder) {
      // Position error linear in the angle: -1.8 deg at 40, +1.8 deg at 76, +/-0.5 deg inside the window.
      r.pos_err_mean_deg = 0.1 * (a - 58);
      r.pos_err_min_deg = *r.pos_err_mean_deg - 0.5;
      r.pos_err_max_deg = *r.pos_err_mean_deg + 0.5;
      r.ld_err_pct = a < 58 ? -7.0 : 3.0;  // 9 points in [-10, -5), 10 in [0, 5)
    }
    out.push_back(r);
  }
}

constexpr Configuration kEkf{Estimator::ekf_basic, Pwm::aspwm};

std::vector<PointRecord> campaign() {
  std::vector<PointRecord> r;
  add_curve(r, {kReferenceConfiguration, 500, 1, 50.0, 1.2, 53.0, 150, 52.36});
  add_curve(r, {kReferenceConfiguration, 500, 2, 51.0, 1.7, 54.0, 260, 104.72});
  add_curve(r, {kReferenceConfiguration, 900, 1, 50.5, 1.25, 54.5, 250, 94.25});
  add_curve(r, {kEkf, 500, 1, 50.7, 1.23, 53.4, 147, 52.36});  // ASPWM: 3 W less input power
  add_curve(r, {kEkf, 500, 2, 51.4, 1.74, 54.3, 257.5, 104.72});
  return r;
}

const CurveResult* find_curve(const Analysis& a, Configuration c, double speed, double load) {
  for (const auto& x : a.curves)
    if (x.configuration == c && x.speed_rpm == speed && x.load_Nm == load) return &x;
  return nullptr;
}

TEST(Analysis, OptimaRefinedWithBothQuantitiesAtEachAngle) {
  const auto a = analyze(campaign());
  EXPECT_EQ(a.records, 5u * 19u);
  EXPECT_EQ(a.used, 5u * 19u);
  ASSERT_EQ(a.curves.size(), 5u);
  // Ordered by configuration, speed, load.
  EXPECT_EQ(a.curves[0].configuration, kReferenceConfiguration);
  EXPECT_EQ(a.curves[2].speed_rpm, 900.0);
  EXPECT_EQ(a.curves[3].configuration, kEkf);
  const auto* c = find_curve(a, kReferenceConfiguration, 500, 1);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->points, 19u);
  EXPECT_EQ(c->angles_deg.size(), 19u);
  EXPECT_TRUE(c->mtpa.refined);
  EXPECT_NEAR(c->mtpa.angle_deg, 50.0, 1e-9);
  EXPECT_NEAR(c->mtpa.im_A, 1.2, 1e-12);
  // P_dcM at the MTPA angle, from the parabola through the same three samples (exact here).
  EXPECT_NEAR(c->mtpa.pdcm_W, 150 + 0.08 * 9, 1e-9);
  EXPECT_NEAR(c->me.angle_deg, 53.0, 1e-9);
  EXPECT_NEAR(c->me.pdcm_W, 150.0, 1e-9);
  EXPECT_NEAR(c->me.im_A, 1.2 * (1 + 4e-4 * 9), 1e-12);
  EXPECT_NEAR(c->me.pm_W, 52.36, 1e-9);
  EXPECT_NEAR(c->me.efficiency, 52.36 / 150, 1e-12);
  EXPECT_FALSE(c->me.at_edge);
}

TEST(Analysis, DeltasAgainstTheReferenceOnBothTrajectories) {
  const auto a = analyze(campaign());
  ASSERT_EQ(a.deltas.size(), 2u);  // ekf at (500, 1) and (500, 2); (900, 1) has no ekf curve
  const auto& d = a.deltas[0];
  EXPECT_EQ(d.configuration, kEkf);
  EXPECT_EQ(d.speed_rpm, 500.0);
  EXPECT_EQ(d.load_Nm, 1.0);
  EXPECT_NEAR(d.mtpa.delta_angle_deg, 0.7, 1e-9);
  EXPECT_NEAR(d.mtpa.delta_im_A, 0.03, 1e-12);
  // MTPA trajectory: each at its own MTPA angle.
  const double p_ekf = 147 + 0.08 * (50.7 - 53.4) * (50.7 - 53.4), p_ref = 150 + 0.08 * 9;
  EXPECT_NEAR(d.mtpa.delta_pdcm_W, p_ekf - p_ref, 1e-9);
  EXPECT_NEAR(d.me.delta_angle_deg, 0.4, 1e-9);
  EXPECT_NEAR(d.me.delta_pdcm_W, -3.0, 1e-9);
  EXPECT_NEAR(d.me.delta_im_A, 1.23 * (1 + 4e-4 * 2.7 * 2.7) - 1.2 * (1 + 4e-4 * 9), 1e-12);
  EXPECT_NEAR(a.deltas[1].me.delta_pdcm_W, -2.5, 1e-9);
  // Another reference: ekf-basic; the encoder curves are then the ones compared.
  AnalysisOptions o;
  o.reference = kEkf;
  const auto b = analyze(campaign(), o);
  ASSERT_EQ(b.deltas.size(), 2u);
  EXPECT_EQ(b.deltas[0].configuration, kReferenceConfiguration);
  EXPECT_NEAR(b.deltas[0].me.delta_pdcm_W, 3.0, 1e-9);
}

TEST(Analysis, FlaggedPointsAreExcludedAndReported) {
  auto recs = campaign();
  // A point that would win both minima if it were believed.
  PointRecord bad = recs[6];
  bad.im_A = 0.5;
  bad.pdcm_W = 50;
  bad.unstable = true;
  recs.push_back(bad);
  PointRecord faulted = recs[8];
  faulted.fault = "overcurrent";
  faulted.voltage_limited = true;
  faulted.pdcm_W = 10;
  recs.push_back(faulted);

  const auto a = analyze(recs);
  EXPECT_EQ(a.used, 5u * 19u);
  ASSERT_EQ(a.excluded.size(), 2u);
  EXPECT_EQ(a.excluded[0].record, 95u);
  EXPECT_EQ(a.excluded[0].reasons, std::vector<std::string>{"unstable"});
  EXPECT_EQ(a.excluded[1].reasons, (std::vector<std::string>{"fault: overcurrent", "voltage_limited"}));
  EXPECT_NEAR(find_curve(a, kReferenceConfiguration, 500, 1)->mtpa.angle_deg, 50.0, 1e-9);

  AnalysisOptions keep;
  keep.exclude_unstable = false;
  const auto b = analyze(recs, keep);
  EXPECT_EQ(b.excluded.size(), 1u);
  // The unstable point (angle 52, averaged with the good one there) now pulls the minimum.
  const auto* c = find_curve(b, kReferenceConfiguration, 500, 1);
  EXPECT_EQ(c->points, 20u);
  EXPECT_EQ(c->angles_deg.size(), 19u);
  EXPECT_NEAR(c->mtpa.im_A, interpolate_at(std::vector<double>{50, 52, 54},
                                          std::vector<double>{1.2, (im_of({{}, 0, 0, 50, 1.2, 0, 0, 0}, 52) + 0.5) / 2,
                                                              im_of({{}, 0, 0, 50, 1.2, 0, 0, 0}, 54)},
                                          1, c->mtpa.angle_deg),
              1e-12);
  EXPECT_LT(c->mtpa.im_A, 1.0);
}

TEST(Analysis, APointRunAtAnotherAngleIsLeftOut) {
  auto recs = campaign();
  // The drive ran far from the 52 deg it was asked for, and the point looks like the curve's best.
  PointRecord off = recs[6];
  off.angle_off = true;
  off.angle_meas_deg = 40.0;
  off.im_A = 0.5;
  off.pdcm_W = 50;
  recs.push_back(off);

  const auto a = analyze(recs);
  ASSERT_EQ(a.excluded.size(), 1u);
  EXPECT_EQ(a.excluded[0].reasons, std::vector<std::string>{"angle_off"});
  EXPECT_NEAR(find_curve(a, kReferenceConfiguration, 500, 1)->mtpa.angle_deg, 50.0, 1e-9);

  AnalysisOptions keep;
  keep.exclude_angle_off = false;
  const auto b = analyze(recs, keep);
  EXPECT_TRUE(b.excluded.empty());
  EXPECT_LT(find_curve(b, kReferenceConfiguration, 500, 1)->mtpa.im_A, 1.0);
}

TEST(Analysis, EdgeOptimaAreFlaggedAndNotRefined) {
  std::vector<PointRecord> recs;
  add_curve(recs, {kReferenceConfiguration, 300, 3, 35.0, 2.0, 80.0, 300, 94.0});
  const auto a = analyze(recs);
  ASSERT_EQ(a.curves.size(), 1u);
  EXPECT_TRUE(a.curves[0].mtpa.at_edge);
  EXPECT_FALSE(a.curves[0].mtpa.refined);
  EXPECT_EQ(a.curves[0].mtpa.angle_deg, 40.0);
  EXPECT_TRUE(a.curves[0].me.at_edge);
  EXPECT_EQ(a.curves[0].me.angle_deg, 76.0);
  EXPECT_DOUBLE_EQ(a.curves[0].me.pdcm_W, 300 + 0.08 * 16);
}

TEST(Analysis, HistogramsPerConfigurationWithThesisBinWidths) {
  const auto a = analyze(campaign());
  // Only ekf-basic has estimator fields: position error and Ld error (no Lq, Rs data).
  ASSERT_EQ(a.histograms.size(), 2u);
  const auto& pos = a.histograms[0];
  EXPECT_EQ(pos.configuration, kEkf);
  EXPECT_EQ(pos.quantity, "pos_err_mean_deg");
  EXPECT_EQ(pos.unit, "deg");
  EXPECT_EQ(pos.bin_width, 0.5);
  EXPECT_EQ(pos.count, 38u);
  EXPECT_NEAR(pos.min, -1.8, 1e-12);
  EXPECT_NEAR(pos.max, 1.8, 1e-12);
  EXPECT_NEAR(pos.mean, 0.0, 1e-12);
  // Errors -1.8, -1.6, ..., 1.8 (19 per curve, two curves) in 0.5 deg bins from -2.0 to 2.0.
  ASSERT_EQ(pos.bins.size(), 8u);
  EXPECT_DOUBLE_EQ(pos.bins.front().from, -2.0);
  EXPECT_DOUBLE_EQ(pos.bins.back().to, 2.0);
  const std::vector<std::size_t> counts{4, 4, 6, 4, 6, 4, 6, 4};  // per curve: 2,2,3,2,3,2,3,2
  for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(pos.bins[i].count, counts[i]) << pos.bins[i].from;
  const auto& ld = a.histograms[1];
  EXPECT_EQ(ld.quantity, "ld_err_pct");
  EXPECT_EQ(ld.bin_width, 5.0);
  ASSERT_EQ(ld.bins.size(), 3u);  // [-10, -5), [-5, 0), [0, 5)
  EXPECT_EQ(ld.bins[0].count, 18u);
  EXPECT_EQ(ld.bins[1].count, 0u);
  EXPECT_EQ(ld.bins[2].count, 20u);
}

TEST(Analysis, PositionErrorAgainstLoadOverTheAngles) {
  const auto a = analyze(campaign());
  ASSERT_EQ(a.position_error.size(), 2u);
  const auto& p = a.position_error[0];
  EXPECT_EQ(p.configuration, kEkf);
  EXPECT_EQ(p.load_Nm, 1.0);
  EXPECT_EQ(p.points, 19u);
  EXPECT_NEAR(p.min_deg, -1.8, 1e-12);
  EXPECT_NEAR(p.mean_deg, 0.0, 1e-12);
  EXPECT_NEAR(p.max_deg, 1.8, 1e-12);
  EXPECT_NEAR(p.window_min_deg, -2.3, 1e-12);
  EXPECT_NEAR(p.window_max_deg, 2.3, 1e-12);
}

TEST(Analysis, EfficiencyMapAtTheMeAngle) {
  const auto a = analyze(campaign());
  ASSERT_EQ(a.efficiency.size(), 5u);
  EXPECT_NEAR(a.efficiency[1].efficiency, 104.72 / 260, 1e-12);
  EXPECT_NEAR(a.efficiency[1].angle_deg, 54.0, 1e-9);
  const auto j = to_json(a)["efficiency_map"]["entries"];
  ASSERT_EQ(j.size(), 2u);
  EXPECT_EQ(j[0]["estimator"], "encoder");
  EXPECT_EQ(j[0]["speeds_rpm"], synbench::Json::parse("[500.0, 900.0]"));
  EXPECT_EQ(j[0]["loads_Nm"], synbench::Json::parse("[1.0, 2.0]"));
  EXPECT_NEAR(j[0]["efficiency"][0][1].get<double>(), 104.72 / 260, 1e-12);
  EXPECT_NEAR(j[0]["efficiency"][1][0].get<double>(), 94.25 / 250, 1e-12);
  EXPECT_TRUE(j[0]["efficiency"][1][1].is_null()) << "900 rpm, 2 N m was not measured";
  EXPECT_EQ(j[1]["pwm"], "aspwm");
  EXPECT_EQ(j[1]["cells"].size(), 2u);
}

TEST(Analysis, JsonIsSelfDescribingAndStable) {
  const auto j = to_json(analyze(campaign()));
  std::vector<std::string> keys;
  for (const auto& [k, v] : j.items()) keys.push_back(k);
  EXPECT_EQ(keys, (std::vector<std::string>{"schema", "options", "points", "curves", "deltas", "histograms",
                                            "position_error", "efficiency_map", "efficiency_contours", "uncertainty"}));
  EXPECT_EQ(j["schema"], "synbench.analysis/1");
  EXPECT_EQ(j["options"]["reference"]["estimator"], "encoder");
  EXPECT_EQ(j["options"]["bin_width"]["rs_err_pct"], 20.0);
  EXPECT_EQ(j["points"]["records"], 95);
  EXPECT_EQ(j["curves"]["thesis_figures"], "6.20");
  const auto& c = j["curves"]["entries"][0];
  EXPECT_EQ(c["estimator"], "encoder");
  EXPECT_EQ(c["pwm"], "capwm");
  EXPECT_NEAR(c["mtpa"]["angle_deg"].get<double>(), 50.0, 1e-9);
  EXPECT_NEAR(c["me"]["pdcm_W"].get<double>(), 150.0, 1e-9);
  EXPECT_EQ(c["me"]["refined"], true);
  EXPECT_NEAR(j["deltas"]["entries"][0]["me"]["delta_pdcm_W"].get<double>(), -3.0, 1e-9);
  EXPECT_EQ(j["deltas"]["reference"]["pwm"], "capwm");
  const auto& h = j["histograms"]["entries"][0];
  EXPECT_EQ(h["quantity"], "pos_err_mean_deg");
  EXPECT_EQ(h["bins"][0]["from"], -2.0);
  EXPECT_EQ(h["bins"][0]["count"], 4);
  const auto& pe = j["position_error"]["entries"];
  ASSERT_EQ(pe.size(), 1u);  // one panel: ekf-basic at 500 rpm
  EXPECT_EQ(pe[0]["speed_rpm"], 500.0);
  EXPECT_EQ(pe[0]["loads"].size(), 2u);
  EXPECT_EQ(pe[0]["loads"][1]["load_Nm"], 2.0);
  // No NaN sneaks into a document: an empty analysis is valid JSON with empty sections.
  const auto empty = to_json(analyze({}));
  EXPECT_EQ(empty["curves"]["entries"].size(), 0u);
  EXPECT_TRUE(synbench::Json::accept(empty.dump()));
}

}  // namespace
}  // namespace synbench::bench
