// Implausible window results: the vectors a window cannot have, and the point procedure on the
// twin refusing a window whose I_m reads -99 A (the point fails naming the field, nothing is
// recorded, the bench ends stopped); a transient failed telemetry read is skipped over.
#include "bench/window_plausibility.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "bench/point_procedure.hpp"
#include "drivers/error.hpp"
#include "emulator/twin_bench.hpp"

namespace synbench::bench {
namespace {

struct Window {
  drivers::SynrmWindow w;
  drivers::LoadWindow l;
  drivers::MeterReading m;
  Window() {
    w.samples = 10000;
    w.window_s = 1.0;
    w.speed_meas_rpm = 700;
    w.im_A = 2.2;
    w.id_A = 1.2;
    w.iq_A = 1.8;  // hypot 2.163
    w.ud_V = -40;
    w.uq_V = 160;
    w.udc_V = 425;
    w.temp_C = 50;
    l.samples = 10000;
    l.torque_Nm = 2.5;
    m.gate_s = 1.0;
    m.idcm_A = 0.5;
    m.idcg_A = 0.3;
  }
  std::optional<std::string> check() const { return implausible_window(w, l, m); }
};

TEST(WindowPlausibility, AMeasuredWindowPasses) {
  EXPECT_FALSE(Window().check());
  Window at_rest;  // a window of a drive that lost its shaft: zeros are plausible
  at_rest.w.speed_meas_rpm = 0;
  at_rest.w.im_A = at_rest.w.id_A = at_rest.w.iq_A = 0;
  EXPECT_FALSE(at_rest.check());
}

TEST(WindowPlausibility, TheFewestSamplesPass) {
  Window device;
  device.w.samples = 100;
  EXPECT_FALSE(device.check());
  Window host;
  host.w.keeper = drivers::WindowKeeper::host;
  host.w.samples = 5;
  EXPECT_FALSE(host.check());
}

TEST(WindowPlausibility, ImpossibleValuesAreNamed) {
  struct Case {
    const char* field;
    void (*spoil)(Window&);
  };
  const Case cases[] = {
      {"window_im_A", [](Window& x) { x.w.im_A = -99; }},
      {"window_im_A", [](Window& x) { x.w.im_A = std::nan(""); }},
      {"window_im_A", [](Window& x) { x.w.im_A = 1.0; }},  // below hypot(1.2, 1.8)
      {"window_id_A", [](Window& x) { x.w.id_A = INFINITY; }},
      {"window_udc_V", [](Window& x) { x.w.udc_V = -20; }},
      {"window_temp_C", [](Window& x) { x.w.temp_C = -50; }},
      {"window_samples", [](Window& x) { x.w.samples = 0; }},
      {"window_samples", [](Window& x) { x.w.samples = 1; }},   // the 1e-300 s window of one period
      {"window_samples", [](Window& x) { x.w.samples = 99; }},  // under the 100 a drive's window holds at 1 kHz
      {"window_samples", [](Window& x) {
         x.w.keeper = drivers::WindowKeeper::host;
         x.w.samples = 4;
       }},
      {"window_s", [](Window& x) { x.w.window_s = 0; }},
      {"window_voltage_limited_fraction", [](Window& x) { x.w.voltage_limited_fraction = 1.5; }},
      {"window_ld_est_H", [](Window& x) { x.w.ld_est_H = std::nan(""); }},
      {"window_torque_Nm", [](Window& x) { x.l.torque_Nm = std::nan(""); }},
      {"idcm_A", [](Window& x) { x.m.idcm_A = std::nan(""); }},
      {"gate_s", [](Window& x) { x.m.gate_s = -1; }},
  };
  for (const auto& c : cases) {
    Window x;
    c.spoil(x);
    const auto why = x.check();
    ASSERT_TRUE(why) << c.field;
    EXPECT_EQ(why->rfind(std::string(c.field) + ":", 0), 0u) << *why;
  }
}

// The twin's SynRM drive, with a window result spoiled on its way to the bench, or a read that
// fails now and then.
class SpoiledDrive final : public drivers::SynrmDrive {
 public:
  explicit SpoiledDrive(drivers::SynrmDrive& d) : d_(d) {}
  std::error_code enable(bool on) override { return d_.enable(on); }
  std::error_code set_speed_rpm(double v) override { return d_.set_speed_rpm(v); }
  std::error_code set_angle_deg(double v) override { return d_.set_angle_deg(v); }
  std::error_code set_pwm(drivers::Pwm p) override { return d_.set_pwm(p); }
  std::error_code set_estimator(drivers::Estimator e) override { return d_.set_estimator(e); }
  std::error_code reset_fault() override { return d_.reset_fault(); }
  std::error_code read(drivers::SynrmTelemetry& out) override {
    ++reads;
    if (fail_every > 0 && reads % fail_every == 0) return make_error_code(errc::timeout);
    return d_.read(out);
  }
  std::error_code read_window(drivers::SynrmWindow& out) override {
    auto ec = d_.read_window(out);
    if (!ec && window_im_A) out.im_A = *window_im_A;
    return ec;
  }
  std::optional<double> window_im_A;
  int fail_every = 0;
  int reads = 0;

 private:
  drivers::SynrmDrive& d_;
};

PointRequest request_700() {
  PointRequest r;
  r.speed_rpm = 700;
  r.load_Nm = 2.5;
  r.angle_deg = 52;
  return r;
}

// A host-kept SynRM window (50 ms polls) over a totalizer meter's 20 s: as measured, and with
// the master frozen past the window's end (the last sample 28.6 s after the first, the meter's
// time base counting on), and with the meter's close latched late while the samples stopped.
TEST(WindowTiming, AHostWindowMustLastWhatTheMeterAndTheRequestSay) {
  Window x;
  x.w.keeper = drivers::WindowKeeper::host;
  x.w.window_s = 20.0;
  x.w.host = {0.05, 0.07};
  x.m.gate_s = 20.01;
  EXPECT_FALSE(window_timing_mismatch(x.w, x.l, x.m, 20.0, 0.5));
  Window frozen = x;
  frozen.w.window_s = 28.6;
  frozen.w.host.longest_gap_s = 20.3;
  frozen.m.gate_s = 28.6;
  const auto why = window_timing_mismatch(frozen.w, frozen.l, frozen.m, 20.0, 0.5);
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("28.6 s by the SynRM drive's host samples but 20 s asked"), std::string::npos) << *why;
  Window split = x;
  split.m.gate_s = 28.6;
  const auto why2 = window_timing_mismatch(split.w, split.l, split.m, 20.0, 0.5);
  ASSERT_TRUE(why2);
  EXPECT_NE(why2->find("20 s by the SynRM drive's host samples but 28.6 s by the meter's time base"),
            std::string::npos)
      << *why2;
  // Within a poll period and the jitter: late by 0.5 s, fine.
  Window late = x;
  late.w.window_s = late.m.gate_s = 20.5;
  EXPECT_FALSE(window_timing_mismatch(late.w, late.l, late.m, 20.0, 0.5));
  // A load drive's host window is held to the same.
  Window load = x;
  load.l.keeper = drivers::WindowKeeper::host;
  load.l.window_s = 12.0;
  load.l.host = {0.05, 8.0};
  const auto why3 = window_timing_mismatch(load.w, load.l, load.m, 20.0, 0.5);
  ASSERT_TRUE(why3);
  EXPECT_NE(why3->find("the load drive's host samples"), std::string::npos) << *why3;
  // Device-kept windows are the devices' own business.
  Window device;
  device.m.gate_s = 3.0;
  EXPECT_FALSE(window_timing_mismatch(device.w, device.l, device.m, 1.0, 0.5));
}

TEST(RecordPowers, AnEfficiencyAboveOneIsRefusedNamingTheFields) {
  PointRecord r;
  r.pdcm_W = 542;
  r.pm_W = 480;
  EXPECT_FALSE(implausible_powers(r));
  r.pm_W = 811.4;  // the 1.497 seen with a frozen master
  const auto why = implausible_powers(r);
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("efficiency: 1.497 > 1: pm_W 811.4 W exceeds pdcm_W 542 W"), std::string::npos) << *why;
  r.pdcm_W = -3;
  const auto why2 = implausible_powers(r);
  ASSERT_TRUE(why2);
  EXPECT_NE(why2->find("pm_W: 811.4 W of mechanical output with pdcm_W -3 W"), std::string::npos) << *why2;
  PointRecord idle;  // nothing in, nothing out: a shaft at rest is no finding
  EXPECT_FALSE(implausible_powers(idle));
}

TEST(WindowPlausibility, APointWhoseWindowReadsMinus99AIsRefusedNotRecorded) {
  emulator::TwinBench bench{emulator::TwinConfig{}};
  SpoiledDrive drive(*bench.devices().synrm);
  drive.window_im_A = -99.0;
  auto dev = bench.devices();
  dev.synrm = &drive;
  const auto p = run_point(dev, bench.clock(), request_700(), PointOptions{});
  EXPECT_EQ(p.phase(), PointPhase::failed);
  EXPECT_FALSE(p.has_record());
  EXPECT_NE(p.error().find("window_im_A"), std::string::npos) << p.error();
  EXPECT_NE(p.error().find("-99"), std::string::npos) << p.error();
  EXPECT_EQ(p.record().im_A, 0.0);  // nothing of the window went into the record
  // Stopped as after a fault: load off, both drives disabled.
  EXPECT_EQ(bench.twin().synrm_drive().state(), drivers::DriveState::disabled);
  EXPECT_NEAR(bench.twin().snapshot().load_torque_Nm, 0.0, 0.01);
}

TEST(WindowPlausibility, TheSameDriveUnspoiledIsRecorded) {
  // The control of the test above: the wrapper itself does not fail points.
  emulator::TwinBench bench{emulator::TwinConfig{}};
  SpoiledDrive drive(*bench.devices().synrm);
  auto dev = bench.devices();
  dev.synrm = &drive;
  const auto p = run_point(dev, bench.clock(), request_700(), PointOptions{});
  ASSERT_EQ(p.phase(), PointPhase::done) << p.error();
  EXPECT_GT(p.record().im_A, 0.5);
}

TEST(PointProcedureLink, ATransientFailedReadIsSkippedALostLinkFailsAtItsDeadline) {
  {
    // Every 7th telemetry read lost: the point is measured all the same.
    emulator::TwinBench bench{emulator::TwinConfig{}};
    SpoiledDrive drive(*bench.devices().synrm);
    drive.fail_every = 7;
    auto dev = bench.devices();
    dev.synrm = &drive;
    const auto p = run_point(dev, bench.clock(), request_700(), PointOptions{});
    ASSERT_EQ(p.phase(), PointPhase::done) << p.error();
    EXPECT_GT(p.tolerated_reads(), 50u);
    EXPECT_NEAR(p.record().speed_meas_rpm, 700, 5);
  }
  {
    // Every read lost from the first: the point fails once telemetry_timeout_s has passed.
    emulator::TwinBench bench{emulator::TwinConfig{}};
    SpoiledDrive drive(*bench.devices().synrm);
    drive.fail_every = 1;
    auto dev = bench.devices();
    dev.synrm = &drive;
    const double t0 = bench.clock().now_s();
    const auto p = run_point(dev, bench.clock(), request_700(), PointOptions{});
    EXPECT_EQ(p.phase(), PointPhase::failed);
    EXPECT_NE(p.error().find("reading SynRM drive telemetry"), std::string::npos) << p.error();
    // The first tick past the deadline, and the runner's wait after it.
    EXPECT_GE(bench.clock().now_s() - t0, 0.5);
    EXPECT_LE(bench.clock().now_s() - t0, 0.53);
  }
}

}  // namespace
}  // namespace synbench::bench
