// Steady-state gate: bands and slopes over the span.
#include "bench/steady_state.hpp"

#include <gtest/gtest.h>

namespace synbench::bench {
namespace {

TEST(SteadyStateGate, NeedsAFullSpanOfSamples) {
  SteadyStateGate g({});
  for (int k = 0; k < 40; ++k) g.add(k * 0.01, 700, 1.9, 260);
  EXPECT_FALSE(g.steady()) << "0.39 s of a 0.5 s span";
  for (int k = 40; k < 60; ++k) g.add(k * 0.01, 700, 1.9, 260);
  EXPECT_TRUE(g.steady());
}

TEST(SteadyStateGate, RejectsARampInsideTheBand) {
  // Speed creeping 3 rpm/s: range 1.5 rpm < 2 rpm band, but the slope moves it 1.5 rpm per span
  // and, at 5 rpm/s, 2.5 rpm per span (> band).
  SteadyStateGate g({});
  for (int k = 0; k <= 50; ++k) g.add(k * 0.01, 700 + 5.0 * k * 0.01, 1.9, 260);
  EXPECT_FALSE(g.steady());
  g.reset();
  for (int k = 0; k <= 50; ++k) g.add(k * 0.01, 700 + 3.0 * k * 0.01, 1.9, 260);
  EXPECT_TRUE(g.steady());
}

TEST(SteadyStateGate, CurrentAndPowerBandsAreRelativeWithAFloor) {
  SteadyStateGate g({});
  // 1 % of 260 W = 2.6 W band; alternating +/- 1.5 W is a 3 W range: not steady.
  for (int k = 0; k <= 50; ++k) g.add(k * 0.01, 700, 1.9, 260 + (k % 2 ? 1.5 : -1.5));
  EXPECT_FALSE(g.steady());
  g.reset();
  for (int k = 0; k <= 50; ++k) g.add(k * 0.01, 700, 1.9, 260 + (k % 2 ? 1.0 : -1.0));
  EXPECT_TRUE(g.steady());
  g.reset();
  // Current: floor of 10 mA at low current.
  for (int k = 0; k <= 50; ++k) g.add(k * 0.01, 700, 0.3 + (k % 2 ? 0.006 : -0.006), 50);
  EXPECT_FALSE(g.steady());
}

}  // namespace
}  // namespace synbench::bench
