// "Measure until sure" in the plan and the adaptive search (pure logic): the precision section
// parsed, refused at its pointers and written back canonically; the estimate an upper bound with
// it; the weighted parabola's vertex uncertainty against the analysis' Monte Carlo on the same
// points; the search stopping once both angle u are below the target (and not before), running
// to its cap when the target cannot be met, replaying from stored records to the same
// proposals; and the outcome's counts (points used against the grid's, precision misses).
#include "bench/sweep_outcome.hpp"

#include <gtest/gtest.h>
#include "drivers/json.hpp"

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "bench/analysis.hpp"
#include "bench/analysis_fit.hpp"

namespace synbench::bench {
namespace {

using json = synbench::Json;

json adaptive_plan(const char* extra) {
  return json::parse(std::string(R"({"dimensions": {"speed_rpm": [300, 700], "load_Nm": [2]}, "mode": "adaptive",
                                      "window_s": 1)") +
                     extra + "}");
}

std::vector<std::string> pointers(const json& doc) {
  std::vector<std::string> out;
  for (const auto& e : parse_sweep_plan(doc).errors) out.push_back(e.pointer + ": " + e.reason);
  return out;
}

TEST(PrecisionPlan, ParsedWithDefaultsAndWrittenBackCanonically) {
  const auto r = parse_sweep_plan(adaptive_plan(R"(, "precision": {"pdcm_u_repeat_target_W": 0.04},
                                                   "adaptive": {"angle_u_target_deg": 0.5})"));
  ASSERT_TRUE(r.plan) << to_string(r.errors.front());
  ASSERT_TRUE(r.plan->precision);
  EXPECT_EQ(r.plan->precision->pdcm_u_repeat_target_W, 0.04);
  EXPECT_EQ(r.plan->precision->max_window_s, 8.0);
  EXPECT_EQ(r.plan->precision->mode, PrecisionMode::lengthen);
  EXPECT_EQ(r.plan->adaptive.angle_u_target_deg, 0.5);
  const json c = to_json(*r.plan);
  EXPECT_EQ(c["precision"], json::parse(R"({"pdcm_u_repeat_target_W": 0.04, "max_window_s": 8.0, "mode": "lengthen"})"));
  EXPECT_EQ(c["adaptive"]["angle_u_target_deg"], 0.5);
  const auto back = parse_sweep_plan(c);
  ASSERT_TRUE(back.plan);
  EXPECT_EQ(*back.plan, *r.plan);
  // Without either: none in the plan, null target in the canonical adaptive section.
  const auto plain = parse_sweep_plan(adaptive_plan(""));
  ASSERT_TRUE(plain.plan);
  EXPECT_FALSE(plain.plan->precision);
  EXPECT_FALSE(to_json(*plain.plan).contains("precision"));
  EXPECT_TRUE(to_json(*plain.plan)["adaptive"]["angle_u_target_deg"].is_null());
}

TEST(PrecisionPlan, RefusedAtItsPointers) {
  EXPECT_EQ(pointers(adaptive_plan(R"(, "precision": {"max_window_s": 4})")),
            std::vector<std::string>{"/precision/pdcm_u_repeat_target_W: required field is missing"});
  EXPECT_EQ(pointers(adaptive_plan(R"(, "precision": {"pdcm_u_repeat_target_W": 0, "mode": "repeat", "window": 1})")),
            (std::vector<std::string>{"/precision/window: unknown field",
                                      "/precision/pdcm_u_repeat_target_W: must be within (0, 1000] W",
                                      "/precision/mode: unknown precision mode 'repeat' (expected lengthen)"}));
  EXPECT_EQ(pointers(adaptive_plan(R"(, "precision": {"pdcm_u_repeat_target_W": 0.1, "max_window_s": 0.5})")),
            std::vector<std::string>{"/precision/max_window_s: must be at least the plan's window_s (1 s)"});
  EXPECT_EQ(pointers(adaptive_plan(R"(, "adaptive": {"angle_u_target_deg": -1})")),
            std::vector<std::string>{"/adaptive/angle_u_target_deg: must be within (0, 45] deg"});
  EXPECT_EQ(pointers(adaptive_plan(R"(, "precision": 3)")).size(), 1u);
}

TEST(PrecisionPlan, EstimateIsAnUpperBoundWithTheLongerWindows) {
  auto doc = json::parse(R"({"dimensions": {"speed_rpm": [300], "load_Nm": [2], "angle_deg": [50, 54]},
                             "window_s": 1, "thermal": {"enabled": false}})");
  const auto plain = estimate(*parse_sweep_plan(doc).plan);
  doc["precision"] = {{"pdcm_u_repeat_target_W", 0.05}, {"max_window_s", 6}};
  const auto plan = *parse_sweep_plan(doc).plan;
  const auto e = estimate(plan);
  EXPECT_FALSE(plain.upper_bound);
  EXPECT_TRUE(e.upper_bound);
  // Two points, each measured at most twice more: the gate's span and 6 s and the overhead.
  const double again_s = plan.gate.bands.span_s + plan.gate.bands.average_s + 6 + SweepTimeModel{}.point_overhead_s;
  EXPECT_NEAR(e.precision_extra_s, 2 * 2 * again_s, 1e-9);
  EXPECT_NEAR(e.bench_time_s, plain.bench_time_s + e.precision_extra_s, 1e-9);
  EXPECT_EQ(to_json(e)["precision_extra_s"], e.precision_extra_s);
}

// ------------------------------------------------------------ the vertex's uncertainty

// im = 2 (1 + 4e-4 (a - 51.3)^2), pdcm = 60 + 0.01 (a - 53.1)^2 with the given repeat u.
PointRecord curve_point(double a, double u_im, double u_pdcm, double noise_im = 0, double noise_pdcm = 0) {
  PointRecord r;
  r.speed_rpm = 300;
  r.load_Nm = 2;
  r.angle_deg = a;
  r.im_A = 2 * (1 + 4e-4 * (a - 51.3) * (a - 51.3)) + noise_im;
  r.pdcm_W = 60 + 0.01 * (a - 53.1) * (a - 53.1) + noise_pdcm;
  r.pm_W = 20;
  r.efficiency = r.pm_W / r.pdcm_W;
  r.im_u_repeat_A = r.im_u_A = u_im;
  r.pdcm_u_repeat_W = r.pdcm_u_W = u_pdcm;
  r.pm_u_W = 0.01;
  r.efficiency_u = r.efficiency_u_repeat = 1e-4;
  return r;
}

TEST(WeightedVertex, AgreesWithTheAnalysisMonteCarloOnTheSamePoints) {
  // Three angles around both minima (the analysis refines through the smallest sample and its
  // neighbours; the search's window holds the same three): the delta method against the Monte
  // Carlo of bench/analysis_uncertainty, at several noise levels small against the curvature.
  for (const double scale : {0.5, 1.0, 2.0}) {
    std::vector<PointRecord> records;
    AngleSearchOptions opt;
    opt.max_evaluations = 3;
    opt.angle_u_target_deg = 0.5;  // the weighted fit and its u
    AngleSearch s(opt);
    for (const double a : {46.0, 52.0, 58.0}) {
      records.push_back(curve_point(a, 0.001 * scale, 0.02 * scale));
      s.report(a, records.back().im_A, records.back().pdcm_W, records.back().im_u_repeat_A,
               records.back().pdcm_u_repeat_W);
    }
    const auto analysis = analyze(records);
    ASSERT_EQ(analysis.curves.size(), 1u);
    const auto& c = analysis.curves.front();
    ASSERT_TRUE(c.mtpa.angle_u_deg && c.me.angle_u_deg);
    const auto r = s.result();
    ASSERT_TRUE(r.mtpa.angle_u_deg && r.me.angle_u_deg);
    EXPECT_NEAR(r.mtpa.angle_deg, c.mtpa.angle_deg, 1e-6);
    EXPECT_NEAR(*r.mtpa.angle_u_deg / *c.mtpa.angle_u_deg, 1.0, 0.3) << scale;
    EXPECT_NEAR(*r.me.angle_u_deg / *c.me.angle_u_deg, 1.0, 0.3) << scale;
    // Twice the noise, twice the angle u (linear propagation).
    if (scale == 1.0) {
      EXPECT_GT(*r.mtpa.angle_u_deg, 0.05);
    }
  }
}

TEST(WeightedVertex, KnownUGivesTheVertexUncertaintyOfThreeExactPoints) {
  // y = (x - 50)^2 at 45, 50, 55 with u = 1: vertex = 50 - c1 / (2 c2); by hand,
  // u(vertex) = u sqrt(Var(c1)) / (2 c2) at the centre with c1 = (y3 - y1) / (2 h): u / (sqrt(2) h) / (2 c2)
  // with h = 5, c2 = 1: 1 / (sqrt(2) * 5 * 2) = 0.0707 deg.
  const std::vector<double> x{45, 50, 55}, y{25, 0, 25}, u{1, 1, 1};
  const auto f = fit_quadratic_weighted(x, y, u);
  ASSERT_TRUE(f && f->vertex_se);
  EXPECT_NEAR(f->q.vertex(), 50, 1e-9);
  EXPECT_NEAR(*f->vertex_se, 1 / (std::sqrt(2.0) * 10), 1e-9);
  // A point with no (or zero) u: no weighted fit.
  EXPECT_FALSE(fit_quadratic_weighted(x, y, std::vector<double>{1, 0, 1}));
}

// ------------------------------------------------------------ the search to an angle u target

struct Curve {
  double u_im, u_pdcm;
  std::mt19937_64 rng;
  std::normal_distribution<double> z;
  PointRecord at(double a) { return curve_point(a, u_im, u_pdcm, u_im * z(rng), u_pdcm * z(rng)); }
};

AngleSearch run_to_end(AngleSearchOptions opt, Curve curve) {
  AngleSearch s(opt);
  while (auto a = s.next_angle()) {
    const auto r = curve.at(*a);
    s.report(r.angle_deg, r.im_A, r.pdcm_W, r.im_u_repeat_A, r.pdcm_u_repeat_W);
  }
  return s;
}

TEST(AngleSearchTarget, StopsOnceBothAnglesAreBelowTheTarget) {
  AngleSearchOptions opt;
  opt.max_evaluations = 30;
  opt.angle_u_target_deg = 0.5;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const auto s = run_to_end(opt, Curve{0.002, 0.05, std::mt19937_64(seed), {}});
    const auto r = s.result();
    EXPECT_TRUE(r.angle_u_target_met) << seed;
    ASSERT_TRUE(r.mtpa.angle_u_deg && r.me.angle_u_deg);
    EXPECT_LE(*r.mtpa.angle_u_deg, 0.5);
    EXPECT_LE(*r.me.angle_u_deg, 0.5);
    EXPECT_LT(r.evaluations, 30u) << seed;
    // Not one point more than needed: the search without its last point had not met the target.
    AngleSearch before(opt);
    const auto& ev = s.evaluations();
    for (std::size_t i = 0; i + 1 < ev.size(); ++i)
      before.report(ev[i].angle_deg, ev[i].im_A, ev[i].pdcm_W, ev[i].im_u_A, ev[i].pdcm_u_W);
    EXPECT_FALSE(before.result().angle_u_target_met) << seed;
    EXPECT_TRUE(before.next_angle());
    // Within about three u of the true optima.
    EXPECT_NEAR(r.mtpa.angle_deg, 51.3, 3 * *r.mtpa.angle_u_deg + 0.1);
    EXPECT_NEAR(r.me.angle_deg, 53.1, 3 * *r.me.angle_u_deg + 0.1);
  }
}

TEST(AngleSearchTarget, ATighterTargetTakesMorePointsAndNoisierPointsRunToTheCap) {
  AngleSearchOptions opt;
  opt.max_evaluations = 40;
  opt.angle_u_target_deg = 0.5;
  const auto loose = run_to_end(opt, Curve{0.002, 0.05, std::mt19937_64(7), {}});
  opt.angle_u_target_deg = 0.2;
  const auto tight = run_to_end(opt, Curve{0.002, 0.05, std::mt19937_64(7), {}});
  EXPECT_TRUE(tight.result().angle_u_target_met);
  EXPECT_GT(tight.evaluations().size(), loose.evaluations().size());
  // Ten times the noise and a cap of 12: the target is out of reach, the cap holds.
  opt.max_evaluations = 12;
  const auto capped = run_to_end(opt, Curve{0.02, 0.5, std::mt19937_64(7), {}});
  EXPECT_EQ(capped.evaluations().size(), 12u);
  EXPECT_FALSE(capped.result().angle_u_target_met);
  // Without u the target cannot be judged: the search runs to its cap.
  AngleSearch blind(opt);
  while (auto a = blind.next_angle()) {
    const auto r = curve_point(*a, 0.002, 0.05);
    blind.report(r.angle_deg, r.im_A, r.pdcm_W);
  }
  EXPECT_EQ(blind.evaluations().size(), 12u);
}

// ------------------------------------------------------------ the outcome from stored records

TEST(SweepOutcome, ReplaysTheStoredPointsAndCountsAgainstTheGrid) {
  auto doc = adaptive_plan(R"(, "adaptive": {"angle_u_target_deg": 0.5, "max_evaluations": 25},
                                "precision": {"pdcm_u_repeat_target_W": 0.04})");
  const SweepPlan plan = *parse_sweep_plan(doc).plan;
  const auto groups = plan_groups(plan);
  ASSERT_EQ(groups.size(), 2u);
  // The first curve searched to its end as the engine would store it; the second not started.
  std::map<std::size_t, PointRecord> stored;
  Curve curve{0.002, 0.05, std::mt19937_64(3), {}};
  AngleSearch live(plan.adaptive);
  while (auto a = live.next_angle()) {
    const PointRecord r = curve.at(*a);
    stored[adaptive_point(plan, groups[0], live.evaluations().size(), *a).index] = r;
    live.report(r.angle_deg, r.im_A, r.pdcm_W, r.im_u_repeat_A, r.pdcm_u_repeat_W);
  }
  // A resume proposes what the live search would: nothing more for the first curve.
  EXPECT_TRUE(replay_search(plan, groups[0], stored).finished());
  EXPECT_EQ(*replay_search(plan, groups[1], stored).next_angle(), *AngleSearch(plan.adaptive).next_angle());

  const auto o = sweep_outcome(plan, stored);
  ASSERT_EQ(o.curves.size(), 1u);
  EXPECT_EQ(o.points_used, live.evaluations().size());
  EXPECT_EQ(o.grid_points, 19u);  // 40, 42, ..., 76 deg
  EXPECT_TRUE(o.curves[0].result.angle_u_target_met);
  EXPECT_EQ(o.curves[0].result.mtpa.angle_u_deg, live.result().mtpa.angle_u_deg);
  ASSERT_TRUE(o.precision);
  // Every point at u 0.05 W against a target of 0.04 W: all missed.
  EXPECT_EQ(o.precision->missed.size(), stored.size());
  const json j = to_json(o);
  EXPECT_EQ(j["adaptive"]["points_used"], live.evaluations().size());
  EXPECT_EQ(j["adaptive"]["curves_target_met"], 1);
  EXPECT_EQ(j["adaptive"]["curves"][0]["points_used"], live.evaluations().size());
  EXPECT_EQ(j["precision"]["points_missed"], stored.size());
  const std::string text = to_text(o);
  EXPECT_NE(text.find("target met"), std::string::npos) << text;
  EXPECT_NE(text.find("against 19 on the 2-deg grid"), std::string::npos) << text;
}

}  // namespace
}  // namespace synbench::bench
