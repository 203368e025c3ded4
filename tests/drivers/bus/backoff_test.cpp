// Tests of the reconnect backoff: doubling, the bound, the reset.
#include <gtest/gtest.h>

#include "drivers/bus/backoff.hpp"

namespace synbench::drivers {
namespace {

TEST(Backoff, FirstAttemptIsImmediate) {
  Backoff b(0.05, 1.0);
  EXPECT_TRUE(b.may_attempt(0.0));
}

TEST(Backoff, DoublesUpToTheBound) {
  Backoff b(0.05, 1.0);
  double t = 10.0;
  const double expected[] = {0.05, 0.1, 0.2, 0.4, 0.8, 1.0, 1.0};
  for (double d : expected) {
    b.failed(t);
    EXPECT_DOUBLE_EQ(b.delay_s(), d);
    EXPECT_FALSE(b.may_attempt(t + d - 1e-9));
    EXPECT_TRUE(b.may_attempt(t + d));
    t += d;
  }
}

TEST(Backoff, SuccessResets) {
  Backoff b(0.05, 1.0);
  for (int i = 0; i < 5; ++i) b.failed(0.0);
  b.succeeded();
  EXPECT_TRUE(b.may_attempt(0.0));
  b.failed(3.0);
  EXPECT_DOUBLE_EQ(b.delay_s(), 0.05);
}

}  // namespace
}  // namespace synbench::drivers
