// Tests of the daemon's telemetry ring: bounded (the oldest dropped), in order across the wrap,
// the input decimated to the ring's rate, the answer decimated to max_points with the newest
// kept, and the file round trip shifting the old trace before the new clock with a gap.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "app/telemetry_history.hpp"

namespace synbench::app {
namespace {

TelemetrySample at(double t_s) {
  TelemetrySample s;
  s.t_s = t_s;
  s.speed_rpm = static_cast<float>(t_s * 10);
  return s;
}

TEST(TelemetryHistory, HoldsAtMostItsCapacityOldestDroppedInOrderAcrossTheWrap) {
  TelemetryHistory h(100, 0.05);
  for (int i = 0; i < 250; ++i) h.offer(at(i * 0.05));
  ASSERT_EQ(h.size(), 100u);
  const auto all = h.recent(1e9, 1000);
  ASSERT_EQ(all.size(), 100u);
  EXPECT_NEAR(all.front().t_s, 150 * 0.05, 1e-9);
  EXPECT_NEAR(all.back().t_s, 249 * 0.05, 1e-9);
  for (std::size_t i = 1; i < all.size(); ++i) EXPECT_LT(all[i - 1].t_s, all[i].t_s);
}

TEST(TelemetryHistory, KeepsOneSampleInEachPeriodOfTheInput) {
  TelemetryHistory h(1000, 0.05);
  for (int i = 0; i < 500; ++i) h.offer(at(i * 0.01));  // 100 Hz for 5 s
  EXPECT_EQ(h.size(), 100u);                            // 20 Hz kept
  const auto all = h.recent(1e9, 1000);
  EXPECT_NEAR(all[1].t_s - all[0].t_s, 0.05, 1e-9);
}

TEST(TelemetryHistory, ASpanAndAPointBudgetDecimateWithTheNewestKept) {
  TelemetryHistory h(2000, 0.05);
  for (int i = 0; i <= 1200; ++i) h.offer(at(i * 0.05));  // 0 .. 60 s
  const auto last10 = h.recent(10.01, 1000);
  EXPECT_EQ(last10.size(), 201u);
  EXPECT_NEAR(last10.front().t_s, 50, 1e-9);
  const auto few = h.recent(61, 100);
  EXPECT_LE(few.size(), 100u);
  EXPECT_GE(few.size(), 90u);
  EXPECT_NEAR(few.back().t_s, 60, 1e-9);
  EXPECT_NEAR(few[1].t_s - few[0].t_s, 13 * 0.05, 1e-9);  // every 13th of 1201
  EXPECT_TRUE(TelemetryHistory(10).recent(60, 100).empty());
}

TEST(TelemetryHistory, SavedAndLoadedBeforeTheNewClockWithTheDownTimeAsAGap) {
  const auto file = std::filesystem::temp_directory_path() / ("synbench-history-test-" + std::to_string(::getpid()) + ".bin");
  TelemetryHistory a(1000, 0.05);
  for (int i = 0; i < 200; ++i) a.offer(at(i * 0.05));  // 0 .. 9.95 s
  ASSERT_FALSE(a.save(file, 1000.0));
  EXPECT_FALSE(std::filesystem::exists(file.string() + ".tmp"));

  TelemetryHistory b(150, 0.05);
  b.offer(at(0.0));
  b.offer(at(0.05));
  ASSERT_FALSE(b.load(file, 0.05, 1030.0));  // down for 30 s
  const auto all = b.recent(1e9, 1000);
  ASSERT_EQ(all.size(), 150u);  // the capacity: the oldest loaded samples dropped
  EXPECT_NEAR(all[147].t_s, -30.0, 1e-9);  // the last loaded one: 30 s before the first new one
  EXPECT_FLOAT_EQ(all[147].speed_rpm, 99.5f);
  EXPECT_NEAR(all[148].t_s, 0.0, 1e-9);
  for (std::size_t i = 1; i < all.size(); ++i) EXPECT_LT(all[i - 1].t_s, all[i].t_s);

  // A damaged file is refused and changes nothing; a missing one is no error.
  { std::ofstream(file, std::ios::binary | std::ios::trunc) << "not a history"; }
  EXPECT_TRUE(b.load(file, 1.0, 2000.0));
  EXPECT_EQ(b.size(), 150u);
  std::filesystem::remove(file);
  EXPECT_FALSE(b.load(file, 1.0, 2000.0));
}

}  // namespace
}  // namespace synbench::app
