// The EEMF observer's two readings of the angle error (emulator/firmware/estimators/
// emf_angle_error.hpp) on EEMF vectors built here for a known error: the estimate ahead by eps
// sees the q-axis EEMF E(eps) = E0 - K eps at (sin eps, cos eps) in its frame.
#include "emulator/firmware/estimators/emf_angle_error.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace synbench::emulator::firmware {
namespace {

struct Emf {
  double eg_V, ed_V;
};

Emf seen_ahead_by(double eps_rad, double e0_V, double k_V_per_rad) {
  const double e = e0_V - k_V_per_rad * eps_rad;
  return {e * std::sin(eps_rad), e * std::cos(eps_rad)};
}

TEST(EmfAngleError, BothReadASmallErrorWhereTheEmfIsLarge) {
  for (double eps : {-0.05, 0.02, 0.05}) {
    const EmfPrediction m{40.0, 30.0};  // a low current angle: K small against E0
    const Emf e = seen_ahead_by(eps, m.emf_V, m.slope_V_per_rad);
    EXPECT_NEAR(emf_vector_angle_error(e.eg_V, e.ed_V, m, 0.0), -eps, 0.1 * std::fabs(eps)) << eps;
    EXPECT_NEAR(emf_line_angle_error(e.eg_V, e.ed_V, 0.0), -eps, 1e-9) << eps;
  }
}

// Above the MTPA angle: the estimate ahead by 66 mrad turns the current onto the q axis and the
// EEMF is gone. Its direction says nothing; its magnitude, against the prediction, says it all.
TEST(EmfAngleError, TheMagnitudeReadsAnErrorThatTookTheEmfAway) {
  const EmfPrediction m{10.0, 150.0};
  const double eps = 10.0 / 150.0;
  const Emf e = seen_ahead_by(eps, m.emf_V, m.slope_V_per_rad);
  EXPECT_NEAR(std::hypot(e.eg_V, e.ed_V), 0.0, 1e-9);
  EXPECT_NEAR(emf_line_angle_error(e.eg_V, e.ed_V, 5.0), 0.0, 1e-9);
  EXPECT_NEAR(emf_vector_angle_error(e.eg_V, e.ed_V, m, 5.0), -eps, 0.01 * eps);
  // Half-way there it reads the same error from both components together.
  const Emf half = seen_ahead_by(0.5 * eps, m.emf_V, m.slope_V_per_rad);
  EXPECT_NEAR(emf_vector_angle_error(half.eg_V, half.ed_V, m, 5.0), -0.5 * eps, 0.02 * eps);
}

TEST(EmfAngleError, NoEmfAndNoPredictionSteerNothingAndOneSampleIsBounded) {
  EXPECT_EQ(emf_vector_angle_error(0.0, 0.0, EmfPrediction{}, 5.0), 0.0);
  EXPECT_EQ(emf_line_angle_error(0.0, 0.0, 5.0), 0.0);
  // The floor fades a reading of noise-level EEMF: 1 V against 5 V.
  EXPECT_NEAR(emf_line_angle_error(-1.0, 1.0, 5.0), (std::numbers::pi / 4) * (2.0 / 27.0), 1e-12);
  // A first-order reading far outside its range is clamped.
  EXPECT_EQ(emf_vector_angle_error(0.0, 400.0, EmfPrediction{40.0, 100.0}, 5.0), 0.5);
  EXPECT_EQ(emf_vector_angle_error(0.0, -400.0, EmfPrediction{40.0, 100.0}, 5.0, 0.3), -0.3);
}

// The line, not the arrow: a q transient that flips the EEMF's sign does not read 180 deg.
TEST(EmfAngleError, AFlippedEmfReadsTheSameLine) {
  const Emf e = seen_ahead_by(0.05, 40.0, 0.0);
  EXPECT_NEAR(emf_line_angle_error(-e.eg_V, -e.ed_V, 0.0), -0.05, 1e-9);
}

// A model that predicts twice the measured EEMF: scaled to the measurement, slope with it. A
// change of the measured level, as a slip's 0.1 s collapse, stays in the reading for about the
// time constant; off, the prediction is untouched.
TEST(EmfScale, ScalesThePredictionToTheMeasuredLevelOverItsTimeConstant) {
  const double ts = 1e-4;
  EmfScale scale;
  scale.configure(0.2, ts);
  EmfPrediction out;
  for (int i = 0; i < 20000; ++i) out = scale.update(30.0, EmfPrediction{60.0, 100.0});
  EXPECT_NEAR(out.emf_V, 30.0, 1e-6);
  EXPECT_NEAR(out.slope_V_per_rad, 50.0, 1e-6);
  for (int i = 0; i < 1000; ++i) out = scale.update(15.0, EmfPrediction{60.0, 100.0});
  EXPECT_GT(out.emf_V, 15.0 + 0.5 * 15.0);  // 0.1 s: exp(-0.5) of the step still to go
  EXPECT_LT(out.emf_V, 30.0 - 0.3 * 15.0);
  for (int i = 0; i < 30000; ++i) out = scale.update(15.0, EmfPrediction{60.0, 100.0});
  EXPECT_NEAR(out.emf_V, 15.0, 1e-3);
  EmfScale off;
  off.configure(0.0, ts);
  out = off.update(30.0, EmfPrediction{60.0, 100.0});
  EXPECT_EQ(out.emf_V, 60.0);
  EXPECT_EQ(out.slope_V_per_rad, 100.0);
}

}  // namespace
}  // namespace synbench::emulator::firmware
