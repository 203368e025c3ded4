// Tests of the window sources on an in-memory bus and simulated time: a host-kept window's
// sampling grid, its averages and sample count, and a totalizer's latched counter reads with
// their wrap-around differences, alone and through ProfileBench's trigger and clock.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "drivers/json.hpp"

#include "drivers/error.hpp"
#include "drivers/profile_devices/profile_bench.hpp"
#include "tests/drivers/profile_devices/fake_bus.hpp"

#ifndef SYNBENCH_TEST_PROFILE_DIR
#error "SYNBENCH_TEST_PROFILE_DIR must name tests/drivers/profiles"
#endif

namespace synbench::drivers {
namespace {

using testing::FakeBus;

DeviceProfile test_profile(const char* file) {
  ProfileParseResult r = load_device_profile(std::filesystem::path(SYNBENCH_TEST_PROFILE_DIR) / file);
  if (!r.profile) throw std::runtime_error(std::string(file) + ": " + r.errors.front().pointer + ": " + r.errors.front().reason);
  return *r.profile;
}

class ManualClock final : public Clock {
 public:
  double now_s() const override { return t; }
  void wait_until(double t_s) override { t = std::max(t, t_s); }
  double t = 0;
};

constexpr std::uint64_t k2to32 = std::uint64_t{1} << 32;

TEST(CounterDifference, CountsOnAcrossTheWrap) {
  EXPECT_EQ(counter_difference(5, 12, k2to32), 7u);
  EXPECT_EQ(counter_difference(k2to32 - 3, 4, k2to32), 7u);
  EXPECT_EQ(counter_difference(k2to32 - 1, 0, k2to32), 1u);
  EXPECT_EQ(counter_difference(65530, 2, 65536), 8u);
  EXPECT_EQ(counter_difference(9, 9, 65536), 0u);
}

struct TotalizerFixture : ::testing::Test {
  FakeBus bus;
  DeviceProfile profile = test_profile("meter_totalizer.json");
  SignalIo io{bus, profile};
  TotalizerWindow window{io};
  void set(double m, double g, double ticks) {
    bus.set(*profile.find("total_m"), m);
    bus.set(*profile.find("total_g"), g);
    bus.set(*profile.find("time_base_ticks"), ticks);
  }
};

TEST_F(TotalizerFixture, DifferencesAcrossTheWrapGiveGateAndCurrents) {
  // Every counter 2^32 - x at the open, and past the wrap at the close.
  set(static_cast<double>(k2to32 - 1000), static_cast<double>(k2to32 - 200'000), static_cast<double>(k2to32 - 400'000));
  ASSERT_FALSE(window.open(10.0, 1.0));
  // One request: the three counters are adjacent, so the meter latches them together.
  ASSERT_EQ(bus.log.size(), 1u);
  EXPECT_EQ(bus.log[0].address, 200);
  EXPECT_EQ(bus.log[0].count, 6u);
  MeterReading m;
  EXPECT_EQ(window.read(m), errc::not_ready);
  bool done = true;
  ASSERT_FALSE(window.poll(10.5, done));
  EXPECT_FALSE(done);
  EXPECT_EQ(bus.log.size(), 1u);  // nothing read before the window's end
  // 1.0 s of a 1 MHz time base; 700 kHz and 450 kHz on the channels (f0 500 kHz, 100 kHz/A).
  set(700'000 - 1000, 450'000 - 200'000, 1'000'000 - 400'000);
  ASSERT_FALSE(window.poll(11.0, done));
  EXPECT_TRUE(done);
  EXPECT_EQ(window.wraps(), 3);
  ASSERT_FALSE(window.read(m));
  EXPECT_EQ(m.counts_m, 700'000u);
  EXPECT_EQ(m.counts_g, 450'000u);
  EXPECT_DOUBLE_EQ(m.gate_s, 1.0);
  EXPECT_DOUBLE_EQ(m.idcm_A, 2.0);
  EXPECT_DOUBLE_EQ(m.idcg_A, -0.5);
  EXPECT_FALSE(m.pdcm_W);
}

TEST_F(TotalizerFixture, AFailedCloseReadIsRepeatedAndAnExpiredWindowIsATimeout) {
  set(0, 0, 0);
  ASSERT_FALSE(window.open(0.0, 0.5));
  bus.fail_next = make_error_code(errc::timeout);
  bool done = false;
  EXPECT_EQ(window.poll(0.5, done), errc::timeout);
  EXPECT_FALSE(done);
  set(600'000, 600'000, 500'000);
  ASSERT_FALSE(window.poll(0.52, done));
  EXPECT_TRUE(done);
  MeterReading m;
  ASSERT_FALSE(window.read(m));
  EXPECT_DOUBLE_EQ(m.gate_s, 0.5);  // the meter's time base, not the late read's
  EXPECT_DOUBLE_EQ(m.idcm_A, 7.0);

  ASSERT_FALSE(window.open(1.0, 0.5));
  window.expire();
  EXPECT_EQ(window.read(m), errc::timeout);
}

struct HostFixture : ::testing::Test {
  FakeBus bus;
  DeviceProfile profile = test_profile("synrm_host_window.json");
  SignalIo io{bus, profile};
  ReadPlan plan{profile, {"speed_rpm", "fault_code", "temp_C"}};
  HostWindow window{io, plan, 0.05};
};

TEST_F(HostFixture, SamplesOnAGridFromOpenToCloseAndAveragesThem) {
  ManualClock clock;
  // The drive's speed ramps: 100 rpm + 10 rpm/s.
  bus.before = [&](const FakeBus::Request&) { bus.set(*profile.find("speed_rpm"), 100 + 10 * clock.t); };
  ASSERT_FALSE(window.open(0.0, 1.0));
  bool done = false;
  // Polled every 10 ms, as the bench's ticks do: a sample only when a grid point is due.
  for (int i = 0; i <= 100 && !done; ++i) {
    clock.t = i * 0.01;
    ASSERT_FALSE(window.poll(clock.t, done));
  }
  EXPECT_TRUE(done);
  ASSERT_FALSE(window.result());
  EXPECT_EQ(window.samples(), 21u);  // 0, 50, ..., 1000 ms
  EXPECT_EQ(bus.log.size(), 21u * plan.requests());  // one read of the plan per sample
  EXPECT_NEAR(window.mean(0), 105.0, 1e-3);  // the ramp's mean over the window
  EXPECT_NEAR(window.min(0), 100.0, 1e-3);
  EXPECT_NEAR(window.max(0), 110.0, 1e-3);
  EXPECT_NEAR(window.span_s(), 1.0, 1e-9);
  EXPECT_TRUE(std::isnan(window.mean(2)));  // temp_C: not in this profile
}

TEST_F(HostFixture, ALateSampleKeepsTheGridAMissedPointIsSkippedAFailedOneRetried) {
  ASSERT_FALSE(window.open(0.0, 0.3));
  bool done = false;
  ASSERT_FALSE(window.poll(0.0, done));    // grid 0
  ASSERT_FALSE(window.poll(0.07, done));   // grid 0.05, late
  EXPECT_DOUBLE_EQ(window.next_due_s(), 0.1);
  ASSERT_FALSE(window.poll(0.17, done));   // 0.10 and 0.15 due: one sample, no made-up second
  EXPECT_EQ(window.samples(), 3u);
  bus.fail_next = make_error_code(errc::timeout);
  EXPECT_EQ(window.poll(0.2, done), errc::timeout);
  EXPECT_EQ(window.samples(), 3u);
  ASSERT_FALSE(window.poll(0.21, done));  // the failed one, at the next poll
  EXPECT_EQ(window.samples(), 4u);
  ASSERT_FALSE(window.poll(0.3, done));
  EXPECT_TRUE(done);
  EXPECT_EQ(window.samples(), 5u);
}

TEST_F(HostFixture, AFaultDuringTheWindowIsKeptAndNoResultBeforeTheClose) {
  bus.set(*profile.find("fault_code"), 0);
  EXPECT_EQ(window.result(), errc::not_ready);
  ASSERT_FALSE(window.open(0.0, 0.1));
  EXPECT_EQ(window.arm(), errc::busy);
  bool done = false;
  ASSERT_FALSE(window.poll(0.0, done));
  bus.set(*profile.find("fault_code"), 4);  // overspeed
  ASSERT_FALSE(window.poll(0.05, done));
  bus.set(*profile.find("fault_code"), 0);
  EXPECT_EQ(window.result(), errc::not_ready);
  ASSERT_FALSE(window.poll(0.1, done));
  ASSERT_FALSE(window.result());
  EXPECT_EQ(window.first_nonzero(1), 4.0);
}

// Two host-kept drives and a totalizer meter as the bench drives them: the trigger opens them,
// the bench's clock takes the samples while the bench waits, and the results read through the
// typed devices say who kept the window.
TEST(ProfileBenchHostWindows, TheClockSamplesWhileTheBenchWaits) {
  FakeBus bus;
  ManualClock clock;
  ProfileBench bench{bus, test_profile("synrm_host_window.json"), bus, test_profile("load_host_window.json"),
                     bus, test_profile("meter_totalizer.json"), clock};
  const DeviceProfile& sp = bench.synrm().profile();
  const DeviceProfile& mp = bench.meter().profile();
  bus.set(*sp.find("udc_V"), 425);
  bus.set(*bench.load().profile().find("torque_Nm"), 2.0);
  bus.before = [&](const FakeBus::Request&) {
    bus.set(*sp.find("speed_rpm"), 600 + 20 * clock.t);
    // Counters of 700 kHz, 450 kHz and 1 MHz, 2^32 - 300000 at t = 0.
    const auto counter = [&](double hz) {
      return static_cast<double>((k2to32 - 300'000 + static_cast<std::uint64_t>(std::llround(hz * clock.t))) % k2to32);
    };
    bus.set(*mp.find("total_m"), counter(700e3));
    bus.set(*mp.find("total_g"), counter(450e3));
    bus.set(*mp.find("time_base_ticks"), counter(1e6));
  };
  ASSERT_FALSE(bench.trigger().open_window(0.5));
  // The procedure ticks every 10 ms; between ticks the bench's clock does the sampling.
  while (!bench.trigger().window_closed()) bench.clock().wait_until(clock.t + 0.01);
  SynrmWindow w;
  LoadWindow lw;
  MeterReading m;
  ASSERT_FALSE(bench.synrm().read_window(w));
  ASSERT_FALSE(bench.load().read_window(lw));
  ASSERT_FALSE(bench.meter().read(m));
  EXPECT_EQ(w.keeper, WindowKeeper::host);
  EXPECT_EQ(w.samples, 11u);
  EXPECT_NEAR(w.speed_meas_rpm, 605, 1e-3);
  EXPECT_NEAR(w.udc_V, 425, 1e-9);
  EXPECT_FALSE(w.temp_C);  // unmapped: no temperature, not 0 degC
  EXPECT_EQ(lw.keeper, WindowKeeper::host);
  EXPECT_EQ(lw.samples, 11u);
  EXPECT_NEAR(lw.torque_Nm, 2.0, 1e-6);
  // 11 polls are too few for 10 batches of at least 2 polls on average: none.
  EXPECT_TRUE(w.batch_im_A.empty());
  EXPECT_TRUE(lw.batch_torque_Nm.empty());
  EXPECT_EQ(m.keeper, WindowKeeper::device);
  EXPECT_EQ(m.f0_Hz, mp.f0_Hz);  // the totalizer's currents come from the profile's calibration
  EXPECT_EQ(m.kf_Hz_per_A, mp.kf_Hz_per_A);
  EXPECT_TRUE(m.batch_counts_m.empty());
  EXPECT_GT(bench.meter().totalizer()->wraps(), 0);
  EXPECT_NEAR(m.gate_s, 0.5, 1e-5);
  EXPECT_NEAR(m.idcm_A, 2.0, 1e-3);
  EXPECT_NEAR(m.idcg_A, -0.5, 1e-3);
}

// The master frozen past the window's end (SIGSTOP): nothing polled for 20 s while the drive's
// watchdog tripped with a code the profile has no label for. The host window closes on the first
// poll after, with that sample: its fault is `unknown` carrying the device's code, and its
// longest gap and span show the bench stopped polling (the point refuses it:
// bench/window_plausibility.hpp), while the totalizer counted the whole 20.3 s.
TEST(ProfileBenchHostWindows, AMasterFrozenPastTheEndLeavesAGapAndTheDevicesCode) {
  FakeBus bus;
  ManualClock clock;
  std::ifstream in(std::filesystem::path(SYNBENCH_TEST_PROFILE_DIR) / "synrm_host_window.json");
  synbench::Json doc = synbench::Json::parse(in);
  doc["signals"]["fault_code"]["values"].erase("watchdog");
  ProfileParseResult synrm = parse_device_profile(doc);
  ASSERT_TRUE(synrm.profile);
  ProfileBench bench{bus, *synrm.profile, bus, test_profile("load_host_window.json"),
                     bus, test_profile("meter_totalizer.json"), clock};
  const DeviceProfile& sp = bench.synrm().profile();
  const DeviceProfile& mp = bench.meter().profile();
  bus.set(*sp.find("udc_V"), 425);
  bus.before = [&](const FakeBus::Request&) {
    const auto counter = [&](double hz) { return static_cast<double>(std::llround(hz * clock.t) % k2to32); };
    bus.set(*mp.find("total_m"), counter(700e3));
    bus.set(*mp.find("total_g"), counter(450e3));
    bus.set(*mp.find("time_base_ticks"), counter(1e6));
  };
  ASSERT_FALSE(bench.trigger().open_window(1.0));
  while (clock.t < 0.3 - 1e-9) bench.clock().wait_until(clock.t + 0.01);
  clock.t = 20.3;  // frozen: no tick, no sample, no heartbeat
  bus.set(*sp.find("fault_code"), 6);
  while (!bench.trigger().window_closed()) bench.clock().wait_until(clock.t + 0.01);
  SynrmWindow w;
  MeterReading m;
  ASSERT_FALSE(bench.synrm().read_window(w));
  ASSERT_FALSE(bench.meter().read(m));
  EXPECT_EQ(w.fault, Fault::unknown);
  ASSERT_TRUE(w.fault_code_raw);
  EXPECT_EQ(*w.fault_code_raw, 6);
  EXPECT_DOUBLE_EQ(w.host.poll_period_s, 0.05);
  EXPECT_NEAR(w.host.longest_gap_s, 20.0, 0.01);
  EXPECT_NEAR(w.window_s, 20.3, 1e-6);
  EXPECT_NEAR(m.gate_s, 20.3, 1e-5);
}

// A host-kept window splits its polls into kHostWindowBatches equal spans of time: the means
// of the ramp over each tenth of the window, the close's sample with the last.
TEST_F(HostFixture, SplitsItsPollsIntoBatchesByTime) {
  ManualClock clock;
  bus.before = [&](const FakeBus::Request&) { bus.set(*profile.find("speed_rpm"), 100 + 10 * clock.t); };
  ASSERT_FALSE(window.open(0.0, 1.0));
  bool done = false;
  for (int i = 0; i <= 100 && !done; ++i) {
    clock.t = i * 0.01;
    ASSERT_FALSE(window.poll(clock.t, done));
  }
  ASSERT_EQ(window.samples(), 21u);
  const std::vector<double> b = window.batch_means(0);
  ASSERT_EQ(b.size(), kHostWindowBatches);
  // Batch k holds the polls at 0.1 k and 0.1 k + 0.05 s; the last also the close at 1 s.
  for (std::size_t k = 0; k + 1 < b.size(); ++k) EXPECT_NEAR(b[k], 100.25 + static_cast<double>(k), 1e-3) << k;
  EXPECT_NEAR(b.back(), 109.5, 1e-3);
  EXPECT_TRUE(window.batch_means(2).size() == kHostWindowBatches && std::isnan(window.batch_means(2)[0]));
}

TEST_F(HostFixture, FewerThanTwoPollsPerBatchKeepNoBatches) {
  HostWindow slow{io, plan, 0.1};  // 11 polls over 1 s
  ManualClock clock;
  ASSERT_FALSE(slow.open(0.0, 1.0));
  bool done = false;
  for (int i = 0; i <= 100 && !done; ++i) {
    clock.t = i * 0.01;
    ASSERT_FALSE(slow.poll(clock.t, done));
  }
  ASSERT_EQ(slow.samples(), 11u);
  EXPECT_TRUE(slow.batch_means(0).empty());
}

// Through the typed devices: a load step 0.35 s into a host-kept window shows in batch 3 (half
// its polls after the step) and in every batch after it.
TEST(ProfileBenchHostWindows, ALoadStepShowsInTheHostWindowsBatches) {
  FakeBus bus;
  ManualClock clock;
  ProfileBench bench{bus, test_profile("synrm_host_window.json"), bus, test_profile("load_host_window.json"),
                     bus, test_profile("meter_totalizer.json"), clock};
  const DeviceProfile& sp = bench.synrm().profile();
  bus.set(*sp.find("udc_V"), 425);
  bus.before = [&](const FakeBus::Request&) {
    bus.set(*bench.load().profile().find("torque_Nm"), clock.t < 0.35 - 1e-9 ? 1.0 : 2.0);
    bus.set(*sp.find("speed_rpm"), 600 + 20 * clock.t);
  };
  ASSERT_FALSE(bench.trigger().open_window(1.0));
  while (!bench.trigger().window_closed()) bench.clock().wait_until(clock.t + 0.01);
  LoadWindow lw;
  SynrmWindow w;
  ASSERT_FALSE(bench.load().read_window(lw));
  ASSERT_FALSE(bench.synrm().read_window(w));
  ASSERT_EQ(lw.samples, 21u);
  const auto& t = lw.batch_torque_Nm;
  ASSERT_EQ(t.size(), 10u);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(t[k], 1.0, 1e-6) << k;
  EXPECT_NEAR(t[3], 1.5, 1e-6);
  for (std::size_t k = 4; k < 10; ++k) EXPECT_NEAR(t[k], 2.0, 1e-6) << k;
  ASSERT_EQ(w.batch_speed_meas_rpm.size(), 10u);
  EXPECT_NEAR(w.batch_speed_meas_rpm[0], 600.5, 1e-3);  // polls at 0 and 0.05 s
  EXPECT_EQ(w.batch_im_A.size(), 10u);
}

}  // namespace
}  // namespace synbench::drivers
