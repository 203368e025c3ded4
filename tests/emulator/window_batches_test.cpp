// Batch means of a measurement window (emulator/firmware/window_batches.hpp): both drives and
// the VFC meter keep B equal sub-windows whose means average (counts sum) to the window's, the
// twin rounds a window to whole batches, a window shorter than B periods keeps none, and a step
// of the load torque inside the window shows in the batch at its time.
#include "emulator/firmware/window_batches.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <numeric>

#include "emulator/twin_bench.hpp"

namespace synbench::emulator {
namespace {

double mean(const std::vector<double>& v) {
  return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

TEST(WindowBatches, EqualBatchesInTimeOrderOrNone) {
  firmware::WindowBatches b;
  b.reset(12, 3);
  for (int i = 0; i < 12; ++i) b.add(i);
  EXPECT_EQ(b.means(), (std::vector<double>{1.5, 5.5, 9.5}));
  EXPECT_EQ(b.means(2.0), (std::vector<double>{3.0, 11.0, 19.0}));
  b.reset(2, 3);  // shorter than B periods
  b.add(1);
  EXPECT_TRUE(b.means().empty());
  b.reset(13, 3);  // not whole batches
  EXPECT_TRUE(b.means().empty());
  EXPECT_EQ(b.batch(), -1);
}

struct Windows {
  drivers::SynrmWindow synrm;
  drivers::LoadWindow load;
  drivers::MeterReading meter;
};

// A running bench at 500 rpm and `load_Nm`, settled; then one window of `window_s`, with
// `during` called once `step_at_s` into it.
Windows run_window(TwinBench& bench, double window_s, double load_Nm, double step_at_s = -1,
                   const std::function<void()>& during = {}) {
  auto d = bench.devices();
  EXPECT_FALSE(d.synrm->set_angle_deg(54));
  EXPECT_FALSE(d.synrm->set_speed_rpm(500));
  EXPECT_FALSE(d.synrm->enable(true));
  EXPECT_FALSE(d.load->enable(true));
  EXPECT_FALSE(d.load->set_torque_Nm(load_Nm));
  const double t0 = bench.clock().now_s() + 2.5;
  bench.clock().wait_until(t0);
  EXPECT_FALSE(d.trigger->open_window(window_s));
  if (during) {
    bench.clock().wait_until(t0 + step_at_s);
    during();
  }
  while (!d.trigger->window_closed()) bench.clock().wait_until(bench.clock().now_s() + 0.01);
  Windows w;
  EXPECT_FALSE(d.synrm->read_window(w.synrm));
  EXPECT_FALSE(d.load->read_window(w.load));
  EXPECT_FALSE(d.meter->read(w.meter));
  return w;
}

TEST(WindowBatches, TwinWindowsCarryBatchesAveragingToTheWindow) {
  TwinConfig cfg;
  cfg.firmware.window_batches = 8;
  TwinBench bench(cfg);
  const Windows w = run_window(bench, 0.4, 1.5);
  const std::size_t b = 8;
  EXPECT_EQ(w.synrm.samples, 4000u);
  ASSERT_EQ(w.synrm.batch_im_A.size(), b);
  ASSERT_EQ(w.synrm.batch_speed_meas_rpm.size(), b);
  ASSERT_EQ(w.load.batch_torque_Nm.size(), b);
  ASSERT_EQ(w.meter.batch_counts_m.size(), b);
  ASSERT_EQ(w.meter.batch_counts_g.size(), b);
  EXPECT_NEAR(mean(w.synrm.batch_im_A), w.synrm.im_A, 1e-12 * w.synrm.im_A);
  EXPECT_NEAR(mean(w.load.batch_torque_Nm), w.load.torque_Nm, 1e-12 * w.load.torque_Nm);
  // The batch speeds come from encoder counts over 500 periods: one count is 0.29 rpm.
  EXPECT_NEAR(mean(w.synrm.batch_speed_meas_rpm), w.synrm.speed_meas_rpm, 0.1);
  for (double s : w.synrm.batch_speed_meas_rpm) EXPECT_NEAR(s, 500.0, 5.0);
  // The batches scatter (noise) but are of one operating point.
  EXPECT_NE(w.synrm.batch_im_A.front(), w.synrm.batch_im_A.back());
  for (double im : w.synrm.batch_im_A) EXPECT_NEAR(im, w.synrm.im_A, 0.02 * w.synrm.im_A);
  // Sub-gates: pulses sum to the gate's exactly, each batch a B-th of the gate's time.
  const auto sum = [](const std::vector<std::uint64_t>& v) {
    return std::accumulate(v.begin(), v.end(), std::uint64_t{0});
  };
  EXPECT_EQ(sum(w.meter.batch_counts_m), w.meter.counts_m);
  EXPECT_EQ(sum(w.meter.batch_counts_g), w.meter.counts_g);
  for (std::uint64_t c : w.meter.batch_counts_m)
    EXPECT_NEAR(static_cast<double>(c), static_cast<double>(w.meter.counts_m) / 8.0,
                1e-2 * static_cast<double>(w.meter.counts_m) / 8.0);
  EXPECT_EQ(w.meter.f0_Hz, cfg.vfc.f0_Hz);
  EXPECT_EQ(w.meter.kf_Hz_per_A, cfg.vfc.kf_Hz_per_A);
  // The meter's current is the one its counts give with the nominal f0, Kf it reports.
  EXPECT_NEAR(w.meter.idcm_A,
              (static_cast<double>(w.meter.counts_m) / w.meter.gate_s - w.meter.f0_Hz) / w.meter.kf_Hz_per_A,
              1e-12);
}

TEST(WindowBatches, TwinRoundsAWindowToWholeBatches) {
  TwinConfig cfg;  // B = 10
  TwinBench bench(cfg);
  const Windows w = run_window(bench, 0.1234, 1.0);
  EXPECT_EQ(w.synrm.samples, 1230u);
  EXPECT_EQ(w.load.samples, 1230u);
  EXPECT_NEAR(w.meter.gate_s, 0.123, 1e-12);
  EXPECT_EQ(w.synrm.batch_im_A.size(), 10u);
}

TEST(WindowBatches, AWindowShorterThanBPeriodsKeepsNone) {
  TwinConfig cfg;
  cfg.firmware.window_batches = 16;
  TwinBench bench(cfg);
  const Windows w = run_window(bench, 0.0012, 1.0);  // 12 periods
  EXPECT_EQ(w.synrm.samples, 12u);
  EXPECT_TRUE(w.synrm.batch_im_A.empty());
  EXPECT_TRUE(w.synrm.batch_speed_meas_rpm.empty());
  EXPECT_TRUE(w.load.batch_torque_Nm.empty());
  EXPECT_TRUE(w.meter.batch_counts_m.empty());
  EXPECT_TRUE(w.meter.batch_counts_g.empty());
  EXPECT_GT(w.meter.counts_m, 0u);
}

TEST(WindowBatches, ALoadStepInsideTheWindowShowsInItsBatch) {
  TwinConfig cfg;  // B = 10: 0.1 s batches of a 1 s window; the torque ramps at 10 Nm/s
  TwinBench bench(cfg);
  drivers::LoadDrive* load = bench.devices().load;
  const Windows w = run_window(bench, 1.0, 1.0, 0.35, [&] { EXPECT_FALSE(load->set_torque_Nm(2.0)); });
  const auto& t = w.load.batch_torque_Nm;
  ASSERT_EQ(t.size(), 10u);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(t[k], 1.0, 0.03) << "batch " << k;
  // Batch 3 (0.3..0.4 s) holds the step's start, batch 4 the rest of the ramp.
  EXPECT_GT(t[3], 1.06);
  EXPECT_LT(t[3], 1.2);
  EXPECT_GT(t[4], 1.7);
  EXPECT_LT(t[4], 1.95);
  for (std::size_t k = 5; k < 10; ++k) EXPECT_NEAR(t[k], 2.0, 0.03) << "batch " << k;
  EXPECT_NEAR(mean(t), w.load.torque_Nm, 1e-12);
}

}  // namespace
}  // namespace synbench::emulator
