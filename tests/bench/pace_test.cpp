// The remaining-time estimate of a sweep at this run's pace.
#include "bench/pace.hpp"

#include <gtest/gtest.h>

namespace synbench::bench {
namespace {

TEST(Pace, NoEstimateBeforeThisRunMeasuredAPoint) {
  EXPECT_FALSE(remaining_s(0.0, 0, 0, 10));
  // Points restored from an interrupted run took no time in this one: still no pace.
  EXPECT_FALSE(remaining_s(120.0, 0, 4, 10));
}

TEST(Pace, IsTheTimePerPointOfThisRunTimesThePointsLeft) {
  EXPECT_DOUBLE_EQ(remaining_s(30.0, 3, 3, 10).value(), 70.0);
  // Resumed: 5 restored, 2 measured in 40 s, 3 left at 20 s each.
  EXPECT_DOUBLE_EQ(remaining_s(40.0, 2, 7, 10).value(), 60.0);
}

TEST(Pace, NothingLeftIsZeroAndMoreDoneThanTotalIsNoEstimate) {
  EXPECT_DOUBLE_EQ(remaining_s(55.0, 10, 10, 10).value(), 0.0);
  EXPECT_FALSE(remaining_s(55.0, 10, 11, 10)) << "an inconsistent count is not a negative time";
}

}  // namespace
}  // namespace synbench::bench
