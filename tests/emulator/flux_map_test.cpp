// Saturation maps against the thesis' sanity values (physics.md 1.1).
#include "emulator/flux_map.hpp"

#include <gtest/gtest.h>

#include "emulator/twin_config.hpp"

namespace synbench::emulator {
namespace {

const SynrmParams kMotor;

TEST(FluxMap, DynamicLqAtHalfAmpIsAboutPoint115H) {
  FluxAxis q(kMotor.flux_q);
  EXPECT_NEAR(q.dynamic_inductance_H(0.5), 0.115, 0.002);
  // "drops to 25 %": about 30 % of Lq0.
  EXPECT_NEAR(q.dynamic_inductance_H(0.5) / kMotor.flux_q.l0_H, 0.30, 0.02);
}

TEST(FluxMap, StaticLdAtRatedCurrentIsAboutPoint47H) {
  FluxAxis d(kMotor.flux_d);
  EXPECT_NEAR(d.static_inductance_H(2.26), 0.47, 0.01);
  EXPECT_NEAR(1.0 - d.static_inductance_H(2.26) / kMotor.flux_d.l0_H, 0.30, 0.02);
}

TEST(FluxMap, SwitchPointsAreTheUpperCrossings) {
  EXPECT_NEAR(FluxAxis(kMotor.flux_d).switch_current_A(), 1.1279, 1e-4);
  EXPECT_NEAR(FluxAxis(kMotor.flux_q).switch_current_A(), 0.25448, 1e-5);
}

TEST(FluxMap, ContinuousAndMonotonicAcrossTheSwitchPoint) {
  for (const auto& p : {kMotor.flux_d, kMotor.flux_q}) {
    FluxAxis ax(p);
    const double s = ax.switch_current_A();
    EXPECT_NEAR(ax.psi(s * (1 - 1e-9)), ax.psi(s * (1 + 1e-9)), 1e-8);
    double last = -1e9;
    for (double i = -5.0; i <= 5.0; i += 0.001) {
      const double psi = ax.psi(i);
      EXPECT_GT(psi, last) << "at " << i;
      last = psi;
    }
  }
}

TEST(FluxMap, InverseMapRoundTrips) {
  for (const auto& p : {kMotor.flux_d, kMotor.flux_q}) {
    FluxAxis ax(p);
    for (double i = -6.0; i <= 6.0; i += 0.0137) EXPECT_NEAR(ax.current(ax.psi(i)), i, 1e-9);
  }
}

TEST(FluxMap, DynamicInductanceIsTheDerivative) {
  FluxAxis d(kMotor.flux_d);
  for (double i : {0.3, 1.5, 2.26, 4.0}) {
    const double h = 1e-6;
    EXPECT_NEAR(d.dynamic_inductance_H(i), (d.psi(i + h) - d.psi(i - h)) / (2 * h), 1e-6);
  }
}

}  // namespace
}  // namespace synbench::emulator
