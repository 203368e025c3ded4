// The twin against what the thesis measured (issue "Foundation", physics.md 9): power balance,
// voltage limit, the nameplate point, MTPA/ME angle shapes, ASPWM savings.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "point_runner.hpp"

namespace synbench {
namespace {

using testing::measure;

double phase_voltage_V(const bench::PointRecord& r) { return std::hypot(r.ud_V, r.uq_V); }

// Angle of the minimum of f over the grid, refined by a parabola through the minimum and its
// neighbours (experiment.md 3).
struct Minimum {
  double angle_deg, value;
};
Minimum refined_minimum(const std::vector<double>& angles, const std::vector<double>& values) {
  std::size_t k = 0;
  for (std::size_t i = 1; i < values.size(); ++i)
    if (values[i] < values[k]) k = i;
  if (k == 0 || k + 1 == values.size()) return {angles[k], values[k]};
  const double h = angles[k + 1] - angles[k];
  const double a = values[k - 1], b = values[k], c = values[k + 1];
  const double den = a - 2 * b + c;
  const double x = den > 0 ? 0.5 * (a - c) / den : 0.0;
  return {angles[k] + x * h, b - 0.25 * (a - c) * x};
}

TEST(BenchPhysics, PowerBalanceAtSteadyState) {
  const emulator::TwinConfig cfg;
  for (auto [speed, load, angle] : {std::tuple{700.0, 2.5, 52.0}, {300.0, 1.0, 60.0}, {900.0, 3.5, 56.0}}) {
    const auto r = measure(cfg, speed, load, angle);
    ASSERT_TRUE(r.truth);
    const auto& t = *r.truth;
    const double sum = t.pcu_W + t.pfe_W + t.pmech_W + t.pm_W;
    EXPECT_NEAR(sum / t.pin_W, 1.0, 0.005) << speed << " rpm " << load << " N m";
    // The VFC-measured input equals the plant's AC input plus the inverter's losses.
    EXPECT_NEAR(r.pdcm_W / (t.pin_W + t.pinvm_W), 1.0, 0.01) << speed << " rpm " << load << " N m";
    // The bench's shaft power (load torque and B1G) matches the plant's.
    EXPECT_NEAR(r.pm_W / t.pm_W, 1.0, 0.01);
    EXPECT_FALSE(r.unstable);
    EXPECT_NEAR(r.speed_meas_rpm, speed, 0.5);
  }
}

TEST(BenchPhysics, VoltageLimitAt420VStopsRatedSpeedAtRatedTorque) {
  emulator::TwinConfig cfg;
  cfg.scale_bus_to(420.0);
  for (double angle : {52.0, 56.0, 60.0}) {
    const auto fast = measure(cfg, 1500, 3.5, angle);
    EXPECT_TRUE(fast.voltage_limited) << angle;
    EXPECT_LT(fast.speed_meas_rpm, 1490.0) << "the limit costs speed, it is not hidden";
    const auto slow = measure(cfg, 900, 3.5, angle);
    EXPECT_FALSE(slow.voltage_limited) << angle;
    EXPECT_NEAR(slow.speed_meas_rpm, 900.0, 0.5);
  }
}

TEST(BenchPhysics, RatedPointAt560VMatchesTheNameplate) {
  emulator::TwinConfig cfg;
  cfg.scale_bus_to(560.0);
  std::vector<double> angles, pdcm;
  std::vector<bench::PointRecord> recs;
  for (double a = 52; a <= 68; a += 2) {
    recs.push_back(measure(cfg, 1500, 3.5, a));
    angles.push_back(a);
    pdcm.push_back(recs.back().pdcm_W);
  }
  const auto me = refined_minimum(angles, pdcm);
  const auto r = measure(cfg, 1500, 3.5, me.angle_deg);
  ASSERT_TRUE(r.truth);
  EXPECT_FALSE(r.voltage_limited);
  EXPECT_NEAR(r.speed_meas_rpm, 1500.0, 0.5);
  EXPECT_NEAR(phase_voltage_V(r), 285.8, 0.05 * 285.8);
  EXPECT_NEAR(r.im_A, 2.26, 0.08 * 2.26);
  const double pf = (r.ud_V * r.id_A + r.uq_V * r.iq_A) / (phase_voltage_V(r) * r.im_A);
  EXPECT_NEAR(pf, 0.67, 0.05);
  const double eff_em = (r.truth->pm_W + r.truth->pmech_W) / r.truth->pin_W;
  EXPECT_NEAR(eff_em, 0.845, 0.025);
}

TEST(BenchPhysics, MtpaAndMeAnglesHaveTheThesisShapeAt900Rpm) {
  const emulator::TwinConfig cfg;
  std::vector<double> angles;
  for (double a = 40; a <= 76; a += 2) angles.push_back(a);
  auto optimal = [&](double load) {
    std::vector<double> im, p;
    for (double a : angles) {
      const auto r = measure(cfg, 900, load, a);
      im.push_back(r.im_A);
      p.push_back(r.pdcm_W);
    }
    return std::pair{refined_minimum(angles, im).angle_deg, refined_minimum(angles, p).angle_deg};
  };
  const auto [mtpa_low, me_low] = optimal(0.5);
  const auto [mtpa_mid, me_mid] = optimal(1.5);
  const auto [mtpa_high, me_high] = optimal(3.5);
  EXPECT_GT(mtpa_low, 45.0);
  EXPECT_GT(mtpa_high, 45.0);
  EXPECT_LT(mtpa_mid, mtpa_low) << "MTPA dips toward 45 deg at medium load";
  EXPECT_LT(mtpa_mid, mtpa_high);
  EXPECT_GT(me_low, mtpa_low) << "ME above MTPA";
  EXPECT_GT(me_mid, mtpa_mid);
  EXPECT_GT(me_high, mtpa_high);
}

TEST(BenchPhysics, AspwmLowersInputPowerBySwitchingLoss) {
  const emulator::TwinConfig cfg;
  const auto ca = measure(cfg, 700, 2.5, 54, drivers::Pwm::capwm);
  const auto as = measure(cfg, 700, 2.5, 54, drivers::Pwm::aspwm);
  ASSERT_TRUE(ca.truth && as.truth);
  // Switching loss of three legs with sinusoidal currents (mean |i| = 2/pi I_m), eq. 3.7 with the
  // config's energies; ASPWM switches two thirds as often, so it saves a third of it.
  const emulator::InverterParams inv;
  const double mean_abs_i = 2.0 / M_PI * ca.im_A;
  const double p_sw = 3 * 2 * inv.pwm_frequency_Hz * (inv.esw0_J + inv.esw_per_A_J * mean_abs_i) *
                      ca.udc_V / inv.esw_ref_V;
  const double saving = ca.pdcm_W - as.pdcm_W;
  EXPECT_NEAR(saving, p_sw / 3.0, 0.1 * p_sw / 3.0);
  EXPECT_GT(saving, 1.0) << "units of watts (Fig. 6.21d)";
  EXPECT_NEAR(ca.truth->pinvm_W - as.truth->pinvm_W, saving, 0.3);
  // Same machine operating point: the saving is in the inverter.
  EXPECT_NEAR(as.truth->pin_W, ca.truth->pin_W, 0.5);
}

}  // namespace
}  // namespace synbench
