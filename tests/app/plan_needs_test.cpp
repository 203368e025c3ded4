// Tests of what a plan needs of the bench, checked before a sweep starts: a thermal precondition
// on a SynRM drive whose profile maps no temp_C is refused, naming the signal and the profile.
#include <gtest/gtest.h>

#include "app/plan_needs.hpp"

namespace synbench::app {
namespace {

TEST(PlanNeeds, AThermalPreconditionWithoutATemperatureIsRefusedNamingTheSignal) {
  bench::SweepPlan plan;
  plan.thermal.enabled = true;
  BenchDescription d;
  EXPECT_FALSE(unmet_plan_needs(plan, d));  // the drive reports temp_C
  d.synrm_without_temperature = "vendor SynRM drive";
  const auto why = unmet_plan_needs(plan, d);
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("temp_C"), std::string::npos) << *why;
  EXPECT_NE(why->find("'vendor SynRM drive'"), std::string::npos) << *why;
  plan.thermal.enabled = false;
  EXPECT_FALSE(unmet_plan_needs(plan, d));
}

}  // namespace
}  // namespace synbench::app
