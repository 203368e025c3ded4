// Plausibility of live telemetry, as vectors of reads on simulated time: frozen values, current
// into a shaft at rest, impossible signs and ranges; and what must not trip (noise, standstill,
// a clamped voltage, short transients).
#include "bench/telemetry_plausibility.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace synbench::bench {
namespace {

using drivers::DriveState;
using drivers::SynrmTelemetry;

// A running drive at 700 rpm with its noise: every f32 value moves in its last bits.
SynrmTelemetry running_at(int i) {
  SynrmTelemetry t;
  t.state = DriveState::running;
  const double n = 1e-3 * std::sin(0.7 * i + 0.3);
  t.speed_rpm = 700 + 0.4 * n;
  t.im_A = 2.1 + n;
  t.id_A = 1.2 + n;
  t.iq_A = 1.7 - n;
  t.ud_V = -40 + 10 * n;
  t.uq_V = 160 + 10 * n;
  t.udc_V = 425.0;  // a u16 register of 0.1 V: may repeat, not watched
  t.temp_C = 50.0;  // likewise
  t.pac_W = 300;
  return t;
}

TEST(TelemetryPlausibility, NoisyRunningDriveIsPlausibleForAMinute) {
  TelemetryPlausibility p;
  for (int i = 0; i < 6000; ++i) ASSERT_FALSE(p.check(0.01 * i, running_at(i))) << i;
}

TEST(TelemetryPlausibility, AValueFrozenBitForBitWhileRunningTrips) {
  TelemetryPlausibility p;
  std::optional<Implausibility> found;
  double at = -1;
  for (int i = 0; i < 300 && !found; ++i) {
    SynrmTelemetry t = running_at(i);
    if (i >= 100) t.im_A = 2.0996;  // stuck from 1.00 s on
    found = p.check(0.01 * i, t);
    if (found) at = 0.01 * i;
  }
  ASSERT_TRUE(found);
  EXPECT_EQ(found->signal, "im_A");
  EXPECT_NE(found->reason.find("frozen"), std::string::npos) << found->reason;
  // After frozen_s (1 s) of identical reads, not before.
  EXPECT_NEAR(at, 2.0, 0.011);
}

TEST(TelemetryPlausibility, FrozenNeedsBothTheReadCountAndTheTime) {
  PlausibilityLimits lim;  // 20 reads and 1 s
  {
    // A bench polling every 1 ms faster than the drive refreshes: 200 identical reads in 0.2 s.
    TelemetryPlausibility p(lim);
    SynrmTelemetry t = running_at(0);
    for (int i = 0; i < 200; ++i) EXPECT_FALSE(p.check(0.001 * i, t)) << i;
  }
  {
    // Slow polling: 10 reads over 5 s are not enough reads.
    TelemetryPlausibility p(lim);
    SynrmTelemetry t = running_at(0);
    for (int i = 0; i < 10; ++i) EXPECT_FALSE(p.check(0.5 * i, t)) << i;
  }
}

TEST(TelemetryPlausibility, StandstillZerosAndStoppedDrivesAreNotFrozen) {
  TelemetryPlausibility p;
  for (int i = 0; i < 500; ++i) {
    // Enabled at standstill: no encoder edges, a speed of exactly 0.
    SynrmTelemetry t = running_at(i);
    t.speed_rpm = 0.0;
    t.im_A = 0.3 + 1e-3 * std::sin(i);
    ASSERT_FALSE(p.check(0.01 * i, t)) << i;
  }
  TelemetryPlausibility q;
  SynrmTelemetry off = running_at(0);
  off.state = DriveState::disabled;  // a disabled drive's values may sit still
  for (int i = 0; i < 500; ++i) ASSERT_FALSE(q.check(0.01 * i, off)) << i;
}

TEST(TelemetryPlausibility, ClampedVoltagesOnTheLimitAreNotFrozen) {
  TelemetryPlausibility p;
  for (int i = 0; i < 500; ++i) {
    SynrmTelemetry t = running_at(i);
    t.voltage_limited = true;
    t.ud_V = -120.0;
    t.uq_V = 220.0;
    ASSERT_FALSE(p.check(0.01 * i, t)) << i;
  }
}

TEST(TelemetryPlausibility, CurrentIntoAShaftAtRestTripsAfterRestTime) {
  TelemetryPlausibility p;
  std::optional<Implausibility> found;
  double at = -1;
  for (int i = 0; i < 500 && !found; ++i) {
    SynrmTelemetry t = running_at(i);
    if (i >= 100) t.speed_rpm = 0.0;  // the encoder died (or the rotor locked) at 1 s
    found = p.check(0.01 * i, t);
    if (found) at = 0.01 * i;
  }
  ASSERT_TRUE(found);
  EXPECT_EQ(found->signal, "speed_rpm");
  EXPECT_NE(found->reason.find("at rest"), std::string::npos) << found->reason;
  EXPECT_NEAR(at, 3.0, 0.011);  // rest_s = 2 s after it started
}

TEST(TelemetryPlausibility, BreakAwayAndSmallCurrentsAtRestAreNot) {
  TelemetryPlausibility p;
  // 1.9 s at rest with 2 A (a heavy break-away), then it turns: no trip; the count restarts.
  for (int i = 0; i < 190; ++i) {
    SynrmTelemetry t = running_at(i);
    t.speed_rpm = 0.0;
    ASSERT_FALSE(p.check(0.01 * i, t)) << i;
  }
  for (int i = 190; i < 200; ++i) ASSERT_FALSE(p.check(0.01 * i, running_at(i)));
  for (int i = 200; i < 390; ++i) {
    SynrmTelemetry t = running_at(i);
    t.speed_rpm = 0.0;
    ASSERT_FALSE(p.check(0.01 * i, t)) << i;
  }
  // At rest for long, but with less than rest_current_A (magnetising only): no finding.
  TelemetryPlausibility q;
  for (int i = 0; i < 1000; ++i) {
    SynrmTelemetry t = running_at(i);
    t.speed_rpm = 0.0;
    t.im_A = 0.8 + 1e-3 * std::sin(i);
    ASSERT_FALSE(q.check(0.01 * i, t)) << i;
  }
}

TEST(TelemetryPlausibility, ImpossibleSignsAndRangesTripAtOnce) {
  struct Case {
    const char* signal;
    void (*spoil)(SynrmTelemetry&);
  };
  const Case cases[] = {
      {"im_A", [](SynrmTelemetry& t) { t.im_A = -99.0; }},
      {"im_A", [](SynrmTelemetry& t) { t.im_A = -0.05; }},
      {"im_A", [](SynrmTelemetry& t) { t.im_A = std::nan(""); }},
      {"udc_V", [](SynrmTelemetry& t) { t.udc_V = -40.0; }},
      {"temp_C", [](SynrmTelemetry& t) { t.temp_C = -50.0; }},  // an open NTC
      {"temp_C", [](SynrmTelemetry& t) { t.temp_C = 400.0; }},
      {"speed_rpm", [](SynrmTelemetry& t) { t.speed_rpm = std::nan(""); }},
  };
  for (const auto& c : cases) {
    for (const DriveState state : {DriveState::running, DriveState::disabled}) {
      TelemetryPlausibility p;
      SynrmTelemetry t = running_at(0);
      t.state = state;
      c.spoil(t);
      const auto found = p.check(0.0, t);
      ASSERT_TRUE(found) << c.signal;
      EXPECT_EQ(found->signal, c.signal);
    }
  }
  // The edges that are still plausible: a register's rounding below 0 A, a bus at 0 V, a cold lab.
  TelemetryPlausibility p;
  SynrmTelemetry t = running_at(0);
  t.state = DriveState::disabled;
  t.im_A = -0.005;
  t.udc_V = 0.0;
  t.temp_C = -20.0;
  EXPECT_FALSE(p.check(0.0, t));
}

TEST(TelemetryPlausibility, ResetForgetsTheHistory) {
  TelemetryPlausibility p;
  SynrmTelemetry t = running_at(0);
  for (int i = 0; i < 90; ++i) ASSERT_FALSE(p.check(0.01 * i, t));
  p.reset();
  for (int i = 90; i < 180; ++i) ASSERT_FALSE(p.check(0.01 * i, t)) << i;  // 0.9 s since the reset
  EXPECT_TRUE(p.check(1.95, t));
}

// A coarse integer register (i16 at 0.01 A) holds a steady current bit for bit: not a finding,
// whatever the time. The resolution comes from the drive (SynrmDrive::resolution()).
TEST(TelemetryPlausibility, ACoarseSteadyIntegerSignalIsNotAFinding) {
  TelemetryPlausibility p;
  drivers::TelemetryResolution r;
  r.id_A = 0.01;
  r.iq_A = 0.01;
  p.set_resolution(r);
  for (int i = 0; i < 600; ++i) {
    SynrmTelemetry t = running_at(i);
    t.id_A = 0.91;  // "id_A frozen at 0.91 A, bit for bit, for 66 reads": a steady current
    t.iq_A = 1.70;
    ASSERT_FALSE(p.check(0.05 * i, t)) << i;
  }
  const auto blind = p.blind_spots();
  ASSERT_EQ(blind.size(), 2u);
  EXPECT_EQ(blind[0].signal, "id_A");
  EXPECT_EQ(blind[1].signal, "iq_A");
  EXPECT_NE(blind[0].describe().find("id_A: 0.01 A steps, coarser than its noise"), std::string::npos)
      << blind[0].describe();
}

// The same frozen value in a float register, or in an integer register finer than the noise,
// still trips: only what cannot show noise is left alone.
TEST(TelemetryPlausibility, AFrozenFloatOrFineIntegerSignalStillTrips) {
  for (const double step : {0.0, 1e-6}) {
    TelemetryPlausibility p;
    drivers::TelemetryResolution r;
    r.id_A = step;
    r.iq_A = 0.01;  // another signal coarse: it does not blind the check to id_A
    p.set_resolution(r);
    std::optional<Implausibility> found;
    for (int i = 0; i < 100 && !found; ++i) {
      SynrmTelemetry t = running_at(i);
      t.id_A = 0.91;
      found = p.check(0.05 * i, t);
    }
    ASSERT_TRUE(found) << "step " << step;
    EXPECT_EQ(found->signal, "id_A");
    EXPECT_TRUE(p.blind_spots().size() == 1 && p.blind_spots()[0].signal == "iq_A");
  }
}

}  // namespace
}  // namespace synbench::bench
