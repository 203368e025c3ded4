// A sweep plan against the bench's setpoint limits: a 1600 rpm plan (within the plan's own
// 1650 rpm default) refused for a 1500 rpm drive at /dimensions/speed_rpm, naming the limit;
// operating points at their own pointer; a plan that fits passes.
#include "bench/sweep_plan_bench_limits.hpp"

#include <gtest/gtest.h>

#include "drivers/json.hpp"

namespace synbench::bench {
namespace {

using json = synbench::Json;

SweepPlan parse_ok(const json& doc) {
  auto r = parse_sweep_plan(doc);
  EXPECT_TRUE(r.errors.empty());
  return r.plan.value_or(SweepPlan{});
}

const BenchSetpointLimits kBench{1500.0, 3.5};

TEST(SweepPlanBenchLimits, GridSpeedAboveTheDriveIsRefusedAtItsPointer) {
  const auto plan = parse_ok(json::parse(R"({"dimensions": {"speed_rpm": [300, 1600], "load_Nm": [1],
      "angle_deg": [50]}, "thermal": {"enabled": false}})"));
  const auto errors = check_bench_limits(plan, kBench, false);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].pointer, "/dimensions/speed_rpm");
  EXPECT_NE(errors[0].reason.find("1600 rpm"), std::string::npos) << errors[0].reason;
  EXPECT_NE(errors[0].reason.find("max_speed_rpm (1500 rpm"), std::string::npos) << errors[0].reason;
}

TEST(SweepPlanBenchLimits, OperatingPointsAndWarmupAtTheirOwnPointers) {
  const auto plan = parse_ok(json::parse(R"({"dimensions": {"operating_points": [{"speed_rpm": 300, "load_Nm": 1},
      {"speed_rpm": 1550, "load_Nm": 1}], "angle_deg": [50]}, "thermal": {"warmup_speed_rpm": 1620}})"));
  const auto errors = check_bench_limits(plan, kBench, false);
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0].pointer, "/dimensions/operating_points/1/speed_rpm");
  EXPECT_EQ(errors[1].pointer, "/thermal/warmup_speed_rpm");
}

TEST(SweepPlanBenchLimits, LoadAboveTheBenchAndPresetValues) {
  const auto plan = parse_ok(json::parse(R"({"dimensions": {"speed_rpm": [300], "load_Nm": [1, 3],
      "angle_deg": [50]}, "thermal": {"enabled": false}})"));
  const auto errors = check_bench_limits(plan, {1500.0, 2.0}, false);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].pointer, "/dimensions/load_Nm");
  // A preset's values are not at a pointer of the document: the preset is named.
  EXPECT_EQ(check_bench_limits(plan, {200.0, 3.5}, true).at(0).pointer, "/preset");
}

TEST(SweepPlanBenchLimits, APlanWithinTheBenchPasses) {
  const auto plan = parse_ok(json::parse(R"({"dimensions": {"speed_rpm": {"from": 300, "to": 1500, "step": 600},
      "load_Nm": [1, 3.5], "angle_deg": [50]}})"));
  EXPECT_TRUE(check_bench_limits(plan, kBench, false).empty());
}

}  // namespace
}  // namespace synbench::bench
