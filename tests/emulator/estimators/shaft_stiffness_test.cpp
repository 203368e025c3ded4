// The shaft's angle-error growth rate a = sqrt(Pp |dT/dth_i| / J) that a tracking observer must
// outrun (emulator/firmware/estimators/shaft_stiffness.hpp), checked against the torque of the
// flux maps computed here independently.
#include "emulator/firmware/estimators/shaft_stiffness.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "emulator/flux_map.hpp"
#include "emulator/twin_config.hpp"

namespace synbench::emulator::firmware {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

ShaftStiffnessParams bench_params() {
  const TwinConfig cfg;
  ShaftStiffnessParams p;
  p.flux_d = cfg.synrm.flux_d;
  p.flux_q = cfg.synrm.flux_q;
  p.pole_pairs = cfg.synrm.pole_pairs;
  p.inertia_kgm2 = cfg.total_inertia_kgm2();
  return p;
}

double torque_Nm(double im, double th) {
  const TwinConfig cfg;
  const FluxAxis d(cfg.synrm.flux_d), q(cfg.synrm.flux_q);
  const double id = im * std::cos(th), iq = im * std::sin(th);
  return 1.5 * cfg.synrm.pole_pairs * (d.psi(id) * iq - q.psi(iq) * id);
}

TEST(ShaftStiffness, GrowthRateFollowsTheTorqueSlopeAboveMtpa) {
  const ShaftStiffness s(bench_params());
  const TwinConfig cfg;
  // 2.6 A at 76 deg: about the rated load at the grid's highest angle.
  const double im = 2.6, th = 76 * kDeg;
  const double slope = (torque_Nm(im, th + 1e-4) - torque_Nm(im, th - 1e-4)) / 2e-4;
  ASSERT_LT(slope, 0.0) << "76 deg is above the MTPA angle";
  const double a = s.growth_rate_rad_s(im * std::cos(th), im * std::sin(th));
  EXPECT_NEAR(a, std::sqrt(cfg.synrm.pole_pairs * -slope / cfg.total_inertia_kgm2()), 0.01 * a);
  // Faster than the thesis' 10 Hz HFI loop and 5 Hz EEMF loop: those lose lock here.
  EXPECT_GT(a, 2.0 * std::numbers::pi * 10.0);
  EXPECT_NEAR(s.bandwidth_rad_s(10.0, im * std::cos(th), im * std::sin(th)), 1.5 * a, 1e-9);
  // The sign of i_q (braking) and of i_d (180 deg) does not matter.
  EXPECT_NEAR(s.growth_rate_rad_s(-im * std::cos(th), -im * std::sin(th)), a, 1e-9);
}

TEST(ShaftStiffness, NoGrowthBelowMtpaOrWithoutCurrentOrInertia) {
  const ShaftStiffness s(bench_params());
  // 40 deg at 2 A is below the MTPA angle: the torque rises with the angle, the shaft pulls the
  // error back and the observer keeps its own bandwidth.
  EXPECT_EQ(s.growth_rate_rad_s(2.0 * std::cos(40 * kDeg), 2.0 * std::sin(40 * kDeg)), 0.0);
  EXPECT_EQ(s.bandwidth_rad_s(62.8, 2.0 * std::cos(40 * kDeg), 2.0 * std::sin(40 * kDeg)), 62.8);
  EXPECT_EQ(s.growth_rate_rad_s(0.0, 0.0), 0.0);
  ShaftStiffnessParams off = bench_params();
  off.inertia_kgm2 = 0;
  EXPECT_FALSE(ShaftStiffness(off).enabled());
  EXPECT_EQ(ShaftStiffness(off).growth_rate_rad_s(0.6, 2.5), 0.0);
}

}  // namespace
}  // namespace synbench::emulator::firmware
