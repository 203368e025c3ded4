// Twin study plans: parsing with JSON pointers, canonical form, grid and Monte Carlo samples,
// deterministic keys and shards, and the merged analysis.
#include "bench/study_plan.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "bench/study_analysis.hpp"
#include "drivers/json.hpp"

namespace synbench::bench {
namespace {

using json = synbench::Json;

const json kSweep = json::parse(R"({"name": "s", "dimensions": {"speed_rpm": [700], "load_Nm": [1.0],
  "angle_deg": [50, 56, 62]}, "thermal": {"enabled": false}})");

json grid_doc() {
  return {{"name", "ld-sens"}, {"sweep", kSweep}, {"grid", {{"rs_pct", {0, 10}}, {"ld_pct", {-25, 0, 25}}}}};
}

StudyPlan parse_ok(const json& doc) {
  auto r = parse_study_plan(doc);
  EXPECT_TRUE(r.errors.empty()) << (r.errors.empty() ? "" : to_string(r.errors.front()));
  return r.plan.value_or(StudyPlan{});
}

bool has_error(const StudyPlanParseResult& r, const std::string& pointer, const std::string& words) {
  for (const auto& e : r.errors)
    if (e.pointer == pointer && e.reason.find(words) != std::string::npos) return true;
  return false;
}

TEST(StudyPlan, GridExpandsFirstParameterOutermostInCanonicalOrder) {
  const StudyPlan p = parse_ok(grid_doc());
  ASSERT_EQ(p.grid.size(), 2u);
  EXPECT_EQ(p.grid[0].first, StudyParameter::ld_pct);  // canonical order, not the document's
  EXPECT_EQ(p.grid[1].first, StudyParameter::rs_pct);
  ASSERT_EQ(sample_count(p), 6u);
  const double expect[6][2] = {{-25, 0}, {-25, 10}, {0, 0}, {0, 10}, {25, 0}, {25, 10}};
  for (std::size_t i = 0; i < 6; ++i) {
    const auto s = sample(p, i);
    ASSERT_EQ(s.deviation.size(), 2u);
    EXPECT_EQ(s.deviation[0].second, expect[i][0]) << i;
    EXPECT_EQ(s.deviation[1].second, expect[i][1]) << i;
    EXPECT_FALSE(s.noise_seed_offset);
  }
}

TEST(StudyPlan, PresetNameAsSweepAndCanonicalRoundTrip) {
  json doc = grid_doc();
  doc["sweep"] = "thesis-grid";
  const StudyPlan p = parse_ok(doc);
  EXPECT_EQ(p.sweep.preset, "thesis-grid");
  EXPECT_EQ(p.sweep.speeds_rpm.size(), 5u);
  const json canonical = to_json(p);
  EXPECT_TRUE(canonical["sweep"].is_object());
  const StudyPlan back = parse_ok(canonical);
  EXPECT_EQ(back, p);
  EXPECT_EQ(to_json(back).dump(), canonical.dump());
  EXPECT_EQ(plan_hash(back), plan_hash(p));
}

TEST(StudyPlan, KeysAreStableVectorsAndChangeWithThePlan) {
  const StudyPlan p = parse_ok(grid_doc());
  const std::string h = plan_hash(p);
  // Vector: a change of the canonical form or the hash shows here (it would orphan every stored
  // study: its samples' keys change).
  EXPECT_EQ(h, "748b07e7f1693acd");
  EXPECT_EQ(sample_key(p, 4), "ld-sens/" + h + "/4");
  EXPECT_EQ(sample_index(p, "ld-sens/" + h + "/4"), 4u);
  EXPECT_FALSE(sample_index(p, "ld-sens/" + h + "/4x"));
  EXPECT_FALSE(sample_index(p, "other/" + h + "/4"));
  // The same document, keys in another order: the same canonical plan, the same hash.
  json reordered = {{"grid", {{"ld_pct", {-25, 0, 25}}, {"rs_pct", {0, 10}}}}, {"sweep", kSweep}, {"name", "ld-sens"}};
  EXPECT_EQ(plan_hash(parse_ok(reordered)), h);
  // Any change to what is measured changes it.
  json changed = grid_doc();
  changed["grid"]["ld_pct"] = {-20, 0, 25};
  EXPECT_NE(plan_hash(parse_ok(changed)), h);
  json other_sweep = grid_doc();
  other_sweep["sweep"]["dimensions"]["load_Nm"] = {1.5};
  EXPECT_NE(plan_hash(parse_ok(other_sweep)), h);
}

TEST(StudyPlan, MonteCarloIsSeededIndependentPerSampleAndWithinItsReach) {
  json doc = {{"name", "mc"},
              {"sweep", kSweep},
              {"monte_carlo",
               {{"samples", 2000},
                {"seed", 7},
                {"parameters",
                 {{"ld_pct", {{"distribution", "uniform"}, {"half_width", 25}}},
                  {"rs_pct", {{"distribution", "normal"}, {"sd", 10}, {"mean", 5}}}}}}},
              {"noise_seed_per_sample", true}};
  const StudyPlan p = parse_ok(doc);
  ASSERT_EQ(sample_count(p), 2000u);
  double sum_ld = 0, sum_rs = 0, sq_rs = 0;
  for (std::size_t i = 0; i < 2000; ++i) {
    const auto s = sample(p, i);
    EXPECT_EQ(s.noise_seed_offset, static_cast<int>(i));
    const double ld = s.deviation[0].second, rs = s.deviation[1].second;
    EXPECT_LE(std::fabs(ld), 25.0);
    EXPECT_LE(std::fabs(rs - 5), 40.0);
    sum_ld += ld;
    sum_rs += rs;
    sq_rs += (rs - 5) * (rs - 5);
  }
  EXPECT_NEAR(sum_ld / 2000, 0.0, 1.0);        // uniform +/-25: SE of the mean 0.32
  EXPECT_NEAR(sum_rs / 2000, 5.0, 1.0);        // SE 0.22
  EXPECT_NEAR(std::sqrt(sq_rs / 2000), 10.0, 0.6);
  // A sample is the same whoever computes it, and another seed gives other draws.
  EXPECT_EQ(sample(p, 1234).deviation, sample(parse_ok(doc), 1234).deviation);
  doc["monte_carlo"]["seed"] = 8;
  EXPECT_NE(sample(p, 3).deviation, sample(parse_ok(doc), 3).deviation);
  // Vectors: draws of seed 7, so a change of the generator shows here (before the seed change).
  const StudyPlan seven = parse_ok(json::parse(doc.dump()).patch(json::parse(R"([{"op": "replace", "path": "/monte_carlo/seed", "value": 7}])")));
  EXPECT_EQ(plan_hash(seven), "b0c2c716b36f1153");
  EXPECT_EQ(sample(seven, 0).deviation[0].second, -21.116532291);
  EXPECT_EQ(sample(seven, 0).deviation[1].second, 13.255264994);
  EXPECT_EQ(sample(seven, 1000).deviation[0].second, 12.975077821);
  EXPECT_EQ(sample(seven, 1000).deviation[1].second, 12.64340645);
}

TEST(StudyPlan, RefusesWithJsonPointers) {
  json doc = {{"name", "bad name"},
              {"sweep", {{"dimensions", {{"speed_rpm", {-1}}}}}},
              {"grid", {{"ld_pct", {-25, 400, -25}}, {"lx_pct", {1}}, {"rs_pct", json::array()}}},
              {"extra", 1}};
  const auto r = parse_study_plan(doc);
  EXPECT_FALSE(r.plan);
  EXPECT_TRUE(has_error(r, "/name", "A-Z a-z 0-9"));
  EXPECT_TRUE(has_error(r, "/sweep/dimensions/speed_rpm/0", "")) << "the sweep's errors under /sweep";
  EXPECT_TRUE(has_error(r, "/grid/ld_pct/1", "within [-75, 300]"));
  EXPECT_TRUE(has_error(r, "/grid/ld_pct/2", "repeats -25"));
  EXPECT_TRUE(has_error(r, "/grid/lx_pct", "unknown study parameter 'lx_pct'"));
  EXPECT_TRUE(has_error(r, "/grid/rs_pct", "must not be empty"));
  EXPECT_TRUE(has_error(r, "/extra", "unknown field"));

  json mc = {{"name", "mc"},
             {"sweep", "thesis-grid"},
             {"monte_carlo",
              {{"samples", 0},
               {"parameters", {{"rs_pct", {{"distribution", "normal"}, {"sd", 80}}},
                               {"ld_pct", {{"distribution", "cauchy"}}}}}}}};
  const auto m = parse_study_plan(mc);
  EXPECT_TRUE(has_error(m, "/monte_carlo/samples", "outside"));
  EXPECT_TRUE(has_error(m, "/monte_carlo/seed", "required"));
  EXPECT_TRUE(has_error(m, "/monte_carlo/parameters/rs_pct", "must stay within [-75, 300]"));
  EXPECT_TRUE(has_error(m, "/monte_carlo/parameters/ld_pct/distribution", "unknown distribution 'cauchy'"));

  const auto neither = parse_study_plan(json{{"name", "x"}, {"sweep", "thesis-grid"}});
  EXPECT_TRUE(has_error(neither, "", "requires grid or monte_carlo"));
  const auto sweep_type = parse_study_plan(json{{"name", "x"}, {"sweep", 3}, {"grid", {{"ld_pct", {0}}}}});
  EXPECT_TRUE(has_error(sweep_type, "/sweep", "preset name or a sweep plan object"));
  const auto preset = parse_study_plan(json{{"name", "x"}, {"sweep", "no-such"}, {"grid", {{"ld_pct", {0}}}}});
  EXPECT_TRUE(has_error(preset, "/sweep/preset", "no-such"));
}

TEST(StudyPlan, ShardsPartitionTheSamples) {
  const StudyPlan p = parse_ok(grid_doc());
  std::set<std::size_t> seen;
  for (std::size_t k = 0; k < 4; ++k) {
    for (auto i : shard_samples(p, {k, 4})) {
      EXPECT_EQ(i % 4, k);
      EXPECT_TRUE(seen.insert(i).second) << "sample " << i << " in two shards";
    }
  }
  EXPECT_EQ(seen.size(), 6u);
  EXPECT_EQ(shard_samples(p, {1, 4}), (std::vector<std::size_t>{1, 5}));
  std::string why;
  EXPECT_EQ(parse_shard("3/4", &why), (Shard{3, 4}));
  EXPECT_FALSE(parse_shard("4/4", &why));
  EXPECT_NE(why.find("below N"), std::string::npos);
  EXPECT_FALSE(parse_shard("1", &why));
  EXPECT_FALSE(parse_shard("a/2", &why));
  EXPECT_FALSE(parse_shard("0/0", &why));
  EXPECT_FALSE(parse_shard("1/2x", &why));
}

PointRecord point(drivers::Estimator e, double angle, double im, double pos_err) {
  PointRecord r;
  r.estimator = e;
  r.speed_rpm = 700;
  r.load_Nm = 1;
  r.angle_deg = angle;
  r.im_A = im;
  r.pdcm_W = 100 * im;
  r.pm_W = 73;
  r.efficiency = 0.73 / im;
  if (e != drivers::Estimator::encoder) {
    r.pos_err_mean_deg = pos_err;
    r.pos_err_min_deg = pos_err - 1;
    r.pos_err_max_deg = pos_err + 1;
    r.speed_err_rpm = -pos_err;
  }
  return r;
}

TEST(StudyAnalysis, GroupsByGridValueAndShiftsAgainstNominal) {
  json doc = {{"name", "a"}, {"sweep", kSweep}, {"grid", {{"ld_pct", {-25, 0, 25}}}}};
  const StudyPlan p = parse_ok(doc);
  std::vector<StudySampleRecords> in;
  for (std::size_t i = 0; i < 3; ++i) {
    const double dev = sample(p, i).deviation[0].second;
    // The MTPA minimum moves with the deviation: at 56 deg nominal, 50 deg for -25 %, 62 for +25.
    const double best = 56 + dev / 25 * 6;
    StudySampleRecords s{sample(p, i), {}};
    for (double a : {50.0, 56.0, 62.0})
      s.records.push_back(point(drivers::Estimator::eemf_lut, a, 1.0 + 0.01 * (a - best) * (a - best), dev / 5));
    in.push_back(s);
  }
  const StudyAnalysis a = analyze_study(p, in);
  EXPECT_EQ(a.samples_planned, 3u);
  EXPECT_EQ(a.points, 9u);
  ASSERT_EQ(a.parameters.size(), 1u);
  const auto& g = a.parameters[0].groups;
  ASSERT_EQ(g.size(), 3u);
  EXPECT_TRUE(g[1].nominal);
  ASSERT_EQ(g[0].cells.size(), 1u);
  EXPECT_NEAR(*g[0].cells[0].pos_err_abs_mean_deg, 5.0, 1e-12);
  EXPECT_NEAR(*g[0].cells[0].pos_err_abs_max_deg, 6.0, 1e-12);
  EXPECT_NEAR(*g[1].cells[0].pos_err_abs_mean_deg, 0.0, 1e-12);
  EXPECT_NEAR(*g[2].cells[0].speed_err_abs_mean_rpm, 5.0, 1e-12);
  EXPECT_NEAR(*g[0].cells[0].mtpa_shift_deg, -6.0, 0.05);
  EXPECT_NEAR(*g[1].cells[0].mtpa_shift_deg, 0.0, 1e-9);
  EXPECT_NEAR(*g[2].cells[0].mtpa_shift_deg, 6.0, 0.05);
  const json j = to_json(a);
  EXPECT_EQ(j["parameters"][0]["parameter"], "ld_pct");
  EXPECT_EQ(j["parameters"][0]["groups"][2]["configurations"][0]["configuration"], "eemf-lut/capwm");
  EXPECT_NE(study_table(a).find("eemf-lut/capwm"), std::string::npos);
}

}  // namespace
}  // namespace synbench::bench
