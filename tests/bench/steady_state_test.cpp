// Steady-state gate: bands and slopes over the span.
#include "bench/steady_state.hpp"

#include <gtest/gtest.h>

#include <cmath>

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

// What an injecting configuration looks like: HFI's speed wobbles by +/-6 rpm at 4.5 Hz (and
// P_dcM with it) around a settled mean. The samples never stay in the 2 rpm band; their 1.24 s
// trailing means do, once there are enough of them.
TEST(SteadyStateGate, AveragedChecksPassAStationaryWobbleButNotATrend) {
  auto wobble = [](double t) { return 6.0 * std::sin(2.0 * 3.141592653589793 * 4.5 * t); };
  SteadyStateGate raw({});
  SteadyStateBands b;
  b.average_s = 1.24;
  SteadyStateGate avg(b);
  double first_pass_s = -1;
  for (int k = 0; k <= 500; ++k) {
    const double t = k * 0.01;
    raw.add(t, 300 + wobble(t), 1.9, 150 + wobble(t));
    avg.add(t, 300 + wobble(t), 1.9, 150 + wobble(t));
    EXPECT_FALSE(raw.steady()) << t;
    if (first_pass_s < 0 && avg.steady()) first_pass_s = t;
  }
  EXPECT_TRUE(avg.steady());
  // A mean over 1.24 s, then a 0.5 s span of means (90 % of each is enough to start).
  EXPECT_GE(first_pass_s, 0.9 * 1.24 + 0.9 * 0.5 - 1e-9);
  EXPECT_LE(first_pass_s, 1.24 + 0.5 + 0.02);
  // The same wobble on a speed still settling at 20 rpm/s is not steady, averaged or not.
  avg.reset();
  for (int k = 0; k <= 500; ++k) avg.add(k * 0.01, 300 + 20.0 * k * 0.01 + wobble(k * 0.01), 1.9, 150);
  EXPECT_FALSE(avg.steady());
  // Without averaging the default gate is unchanged: a flat signal passes after one span.
  SteadyStateGate flat(SteadyStateBands{});
  for (int k = 0; k < 60; ++k) flat.add(k * 0.01, 700, 1.9, 260);
  EXPECT_TRUE(flat.steady());
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
