// MCIDC phase-reluctance samples: phase selection per scheme, errors as configured.
#include "emulator/mcidc.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace synbench::emulator {
namespace {

TEST(Mcidc, ReluctanceSpansOneOverLdToOneOverLq) {
  // min R'_ph = 1/Ld on the phase's d alignment, max = 1/Lq in quadrature (5.8, 5.9).
  EXPECT_NEAR(phase_reluctance(0.0, 0, 0.5, 0.125), 2.0, 1e-12);
  EXPECT_NEAR(phase_reluctance(M_PI / 2, 0, 0.5, 0.125), 8.0, 1e-12);
  // Phase b is aligned when th_e = +2pi/3.
  EXPECT_NEAR(phase_reluctance(2 * M_PI / 3, 1, 0.5, 0.125), 2.0, 1e-12);
  // 3 / (2 L_ph) with L_ph = 3 Ld Lq / (Ld + Lq - (Ld - Lq) cos 2x) (5.2 to 5.4).
  const double x = 0.7, ld = 0.45, lq = 0.12;
  const double lph = 3 * ld * lq / (ld + lq - (ld - lq) * std::cos(2 * x));
  EXPECT_NEAR(phase_reluctance(x, 0, ld, lq), 3.0 / (2.0 * lph), 1e-12);
}

TEST(Mcidc, AspwmCyclesThePhasesWithUnbiasedNoise) {
  McidcParams p;
  p.deformation_amplitude_per_H = 0.0;
  Mcidc m(p, 1e-4);
  Noise noise(3);
  const Phases mid{0.5, 0.5, 0.5};  // even at zero voltage ASPWM measures
  double sum = 0, sum2 = 0;
  const int n = 30000;
  for (int k = 0; k < n; ++k) {
    const auto s = m.measure(static_cast<std::uint64_t>(k), drivers::Pwm::aspwm, mid, 0.3, 0.45, 0.12, noise);
    ASSERT_TRUE(s);
    EXPECT_EQ(s->phase, k % 3);
    const double e = s->reluctance_per_H - phase_reluctance(0.3, s->phase, 0.45, 0.12);
    sum += e;
    sum2 += e * e;
  }
  EXPECT_NEAR(sum / n, 0.0, 0.005);
  EXPECT_NEAR(std::sqrt(sum2 / n), 0.15, 0.005);
}

TEST(Mcidc, CapwmMissesShortActiveVectorsAndPicksTheLongerOne) {
  McidcParams p;
  p.noise_sigma_per_H = 0;
  p.deformation_amplitude_per_H = 0;
  p.gain_error = 0.1;
  Mcidc m(p, 1e-4);
  Noise noise(1);
  EXPECT_FALSE(m.measure(0, drivers::Pwm::capwm, {0.52, 0.49, 0.49}, 0, 0.45, 0.12, noise))
      << "3 us active vector is too short";
  const auto s = m.measure(0, drivers::Pwm::capwm, {0.5, 0.8, 0.1}, 0.2, 0.45, 0.12, noise);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->phase, 2) << "c alone low for 40 us beats b alone high for 30 us";
  EXPECT_NEAR(s->reluctance_per_H, 1.1 * phase_reluctance(0.2, 2, 0.45, 0.12), 1e-12);
}

// With the window shift the modulator opens a window for one leg per period (a, b, c in turn),
// also near 50 % duty where the plain CAPWM sample is missing.
TEST(Mcidc, CapwmWindowShiftMeasuresEveryPhaseInTurn) {
  McidcParams p;
  p.noise_sigma_per_H = 0;
  p.deformation_amplitude_per_H = 0;
  Mcidc m(p, 1e-4);
  Noise noise(1);
  const Phases near_half{0.52, 0.49, 0.49};
  for (std::uint64_t k = 0; k < 6; ++k) {
    const auto s = m.measure(k, drivers::Pwm::capwm, near_half, 0.3, 0.45, 0.12, noise, true);
    ASSERT_TRUE(s) << k;
    EXPECT_EQ(s->phase, static_cast<int>(k % 3));
    EXPECT_NEAR(s->reluctance_per_H, phase_reluctance(0.3, s->phase, 0.45, 0.12), 1e-12);
  }
}

TEST(InverterModel, AspwmHasTwoThirdsOfTheEdges) {
  EXPECT_EQ(edges_per_period(drivers::Pwm::capwm), 12);
  EXPECT_EQ(edges_per_period(drivers::Pwm::aspwm), 8);
  InverterParams p;
  p.vce0_V = p.rce_ohm = p.vf0_V = p.rf_ohm = 0;  // switching loss only
  InverterModel inv(p);
  const Phases i{1.0, -0.5, -0.5}, d{0.6, 0.45, 0.45};
  EXPECT_NEAR(inv.loss_W(i, d, 400, drivers::Pwm::aspwm) / inv.loss_W(i, d, 400, drivers::Pwm::capwm),
              2.0 / 3.0, 1e-12);
  // CAPWM: 2 events per leg per 100 us with E = 20 uJ + 40 uJ/A |i| at 400 V.
  EXPECT_NEAR(inv.loss_W(i, d, 400, drivers::Pwm::capwm), 2e4 * (3 * 20e-6 + 40e-6 * 2.0), 1e-9);
}

TEST(InverterModel, SvmDutiesReproduceTheVectorUpToTheLimit) {
  const double udc = 420, lim = InverterModel::voltage_limit_V(udc);
  EXPECT_NEAR(lim, 242.49, 0.01);
  for (double ang = 0; ang < 6.3; ang += 0.1) {
    const double ua = lim * std::cos(ang), ub = lim * std::sin(ang);
    const Phases d = InverterModel::duties(ua, ub, udc);
    Phases u;
    for (int n = 0; n < 3; ++n) {
      EXPECT_GE(d[n], -1e-12);
      EXPECT_LE(d[n], 1 + 1e-12);
      u[n] = d[n] * udc;
    }
    double a, b;
    to_alpha_beta(u, a, b);  // the zero sequence drops out
    EXPECT_NEAR(a, ua, 1e-9);
    EXPECT_NEAR(b, ub, 1e-9);
  }
}

}  // namespace
}  // namespace synbench::emulator
