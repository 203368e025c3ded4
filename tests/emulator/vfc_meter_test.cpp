// VFC meter: counting over a gate, quantization, calibration errors (physics.md 4).
#include "emulator/vfc_meter.hpp"

#include <gtest/gtest.h>

namespace synbench::emulator {
namespace {

TEST(VfcMeter, CountsOverOneSecondResolveTenMicroamps) {
  VfcMeter m(VfcParams{});
  m.open_gate(0.0);
  for (int k = 0; k < 10000; ++k) m.integrate(1.23456, -0.5, 1e-4);
  m.close_gate(1.0);
  // f = 500 kHz + 100 kHz/A * i: 623456 pulses, 450000 pulses.
  EXPECT_NEAR(static_cast<double>(m.reading().counts_m), 623456.0, 1.0);
  EXPECT_NEAR(static_cast<double>(m.reading().counts_g), 450000.0, 1.0);
  EXPECT_NEAR(m.reading().idcm_A, 1.23456, 1e-5);
  EXPECT_NEAR(m.reading().idcg_A, -0.5, 1e-5);
}

TEST(VfcMeter, ShortGateShowsCountQuantization) {
  VfcMeter m(VfcParams{});
  m.integrate(0.0, 0.0, 0.3e-4);  // converter phase not aligned with the gate
  m.open_gate(0.0);
  for (int k = 0; k < 10; ++k) m.integrate(0.123456, 0.0, 1e-4);
  m.close_gate(1e-3);
  // One count over 1 ms is 10 mA: the reading is a whole number of counts away from zero.
  const double counts = static_cast<double>(m.reading().counts_m);
  EXPECT_NEAR(m.reading().idcm_A, (counts / 1e-3 - 5e5) / 1e5, 1e-12);
  EXPECT_NEAR(m.reading().idcm_A, 0.123456, 0.0101);
  EXPECT_NE(m.reading().idcm_A, 0.123456);
}

TEST(VfcMeter, CalibrationErrorsShowInTheReading) {
  VfcParams p;
  p.motor.gain_error = 0.01;
  p.motor.offset_error_A = 0.002;
  VfcMeter m(p);
  m.open_gate(0.0);
  for (int k = 0; k < 10000; ++k) m.integrate(1.0, 1.0, 1e-4);
  m.close_gate(1.0);
  EXPECT_NEAR(m.reading().idcm_A, 1.01 * 1.002, 2e-5);
  EXPECT_NEAR(m.reading().idcg_A, 1.0, 2e-5);
}

}  // namespace
}  // namespace synbench::emulator
