// Tests of the point's uncertainty budget: type A of a mean from batch means, the VFC's batch
// currents, each component's value and how it propagates (GUM 5.1.2), and null where a type A
// component is unavailable.
#include <gtest/gtest.h>

#include <cmath>

#include "bench/uncertainty.hpp"

namespace synbench::bench {
namespace {

constexpr double kPi = 3.14159265358979323846;

const BudgetComponent& find(const PointBudget& b, const std::string& name) {
  for (const auto& c : b.components)
    if (c.name == name) return c;
  ADD_FAILURE() << "no component " << name;
  static const BudgetComponent none;
  return none;
}

// Every type B input zero: each test switches on the one it looks at.
drivers::UncertaintyConfig zero_config() {
  drivers::UncertaintyConfig c;
  c.vfc_f0_u_Hz = c.vfc_kf_u_pct = c.meter_clock_u_ppm = c.dc_sensor_gain_u_pct = c.dc_sensor_offset_u_A = 0;
  c.power_meter_u_pct = c.udc_gain_u_pct = c.udc_offset_u_V = c.torque_gain_u_pct = c.torque_offset_u_Nm = 0;
  c.load_b1_u_Nms_per_rad = c.im_gain_u_pct = 0;
  c.encoder_counts_per_rev = 0;  // no encoder quantisation
  return c;
}

// A 700 rpm, 2.5 N m point with a 1 s VFC gate in 4 sub-gates and 4 batches on each drive.
struct Point {
  drivers::SynrmWindow w;
  drivers::LoadWindow lw;
  drivers::MeterReading m;
  BudgetInputs in;
  Point() {
    m.gate_s = 1.0;
    m.f0_Hz = 500e3;
    m.kf_Hz_per_A = 100e3;
    // I_dcM 0.5 A, 0.5 A, 0.5 A, 0.5 A: constant; I_dcG 0.2 A.
    m.batch_counts_m = {137500, 137500, 137500, 137500};
    m.batch_counts_g = {130000, 130000, 130000, 130000};
    w.batch_im_A = {2.0, 2.0, 2.0, 2.0};
    w.batch_speed_meas_rpm = {700, 700, 700, 700};
    lw.batch_torque_Nm = {2.5, 2.5, 2.5, 2.5};
    in.udc_V = 420;
    in.idcm_A = 0.5;
    in.idcg_A = 0.2;
    in.torque_Nm = 2.5;
    in.speed_rpm = 700;
    in.im_A = 2.0;
    in.load_b1_Nms_per_rad = 2e-4;
    const double wm = 700 * 2 * kPi / 60;
    in.pdcm_W = 210;
    in.pdcg_W = 84;
    in.pm_W = 2.5 * wm + 2e-4 * wm * wm;
    in.window_s = 1.0;
    in.synrm = &w;
    in.load = &lw;
    in.meter = &m;
  }
};

TEST(Uncertainty, TypeAOfAMeanIsTheBatchMeansStandardErrorAndNeedsTwo) {
  // mean 2.5, s = sqrt(5/3), u = s / sqrt(4).
  const std::vector<double> x{1, 2, 3, 4};
  ASSERT_TRUE(type_a_of_mean(x));
  EXPECT_NEAR(*type_a_of_mean(x), std::sqrt(5.0 / 3.0) / 2.0, 1e-12);
  EXPECT_DOUBLE_EQ(*type_a_of_mean(std::vector<double>{3, 3, 3}), 0.0);
  EXPECT_FALSE(type_a_of_mean(std::vector<double>{1.0}));
  EXPECT_FALSE(type_a_of_mean(std::vector<double>{}));
}

TEST(Uncertainty, BatchCountsBecomeTheSubGatesCurrents) {
  // 0.25 s sub-gates: f = N / 0.25 s; I = (f - 500 kHz) / 100 kHz/A.
  const std::vector<std::uint64_t> n{150000, 137500, 125000};  // over a 0.75 s gate
  const auto i = batch_currents_A(n, 0.75, 500e3, 100e3);
  ASSERT_EQ(i.size(), 3u);
  EXPECT_NEAR(i[0], 1.0, 1e-12);
  EXPECT_NEAR(i[1], 0.5, 1e-12);
  EXPECT_NEAR(i[2], 0.0, 1e-12);
  EXPECT_TRUE(batch_currents_A(n, 0.75, 500e3, 0).empty());
}

TEST(Uncertainty, TheCountQuantisationIsOneCountOverSqrtSixOfTheGate) {
  Point p;
  const auto b = point_budget(p.in, zero_config());
  const auto& q = find(b, "VFC count quantisation (M)");
  ASSERT_TRUE(q.u);
  EXPECT_NEAR(*q.u, 1.0 / (std::sqrt(6.0) * 100e3 * 1.0), 1e-15);  // 4.08 uA
  EXPECT_TRUE(q.repeat);
  EXPECT_EQ(q.type, 'B');
  // Constant batches: the only component left on P_dcM is the quantisation, times U_dc.
  ASSERT_TRUE(b.u(Output::pdcm_W));
  EXPECT_NEAR(*b.u(Output::pdcm_W), 420 * *q.u, 1e-12);
  EXPECT_NEAR(*b.u_repeat(Output::pdcm_W), 420 * *q.u, 1e-12);
}

TEST(Uncertainty, TheGateTimeEntersThroughF0OverKfPlusTheCurrent) {
  // I = (N / T_g - f0) / Kf evaluated at a gate the clock made longer by d: the component is
  // the current's change, (f0 / Kf + I) d, 5.5 A x 100 ppm at 0.5 A.
  Point p;
  auto cfg = zero_config();
  cfg.meter_clock_u_ppm = 100;
  const auto b = point_budget(p.in, cfg);
  const auto& c = find(b, "meter clock (gate time) (M)");
  ASSERT_TRUE(c.u);
  const double n = (500e3 + 100e3 * 0.5) * 1.0, d = 100e-6;
  const double shifted = (n / (1.0 * (1 + d)) - 500e3) / 100e3;
  EXPECT_NEAR(*c.u, std::abs(shifted - 0.5), 2e-4 * *c.u);  // to first order in d
  EXPECT_NEAR(*c.u, 5.5 * 100e-6, 1e-12);
  EXPECT_FALSE(c.repeat);  // the same clock on every point: systematic
  // Systematic: in the combined value, not its repeat part.
  EXPECT_GT(*b.u(Output::pdcm_W), 420 * 5.0e-4);
  EXPECT_LT(*b.u_repeat(Output::pdcm_W), 0.01);
}

TEST(Uncertainty, TypeAComesFromTheBatchScatterAndPropagatesThroughUdc) {
  Point p;
  // I_dcM batches 0.49, 0.51, 0.49, 0.51 A: s = 0.011547, u = s / 2.
  p.m.batch_counts_m = {137250, 137750, 137250, 137750};
  const auto b = point_budget(p.in, zero_config());
  const auto& a = find(b, "I_dcM type A");
  ASSERT_TRUE(a.u);
  const double u_a = std::sqrt(4 * 0.01 * 0.01 / 3.0) / 2.0;
  EXPECT_NEAR(*a.u, u_a, 1e-9);
  EXPECT_EQ(a.type, 'A');
  EXPECT_DOUBLE_EQ(a.sensitivity[static_cast<std::size_t>(Output::pdcm_W)], 420);
  const double q = 1.0 / (std::sqrt(6.0) * 100e3);
  EXPECT_NEAR(*b.u(Output::pdcm_W), 420 * std::hypot(u_a, q), 1e-9);
  // efficiency = P_m / P_dcM: u(eff) = eff x u(P_dcM) / P_dcM with P_m exact here.
  EXPECT_NEAR(*b.u(Output::efficiency), p.in.pm_W / 210 * *b.u(Output::pdcm_W) / 210, 1e-12);
  EXPECT_NEAR(*b.u_repeat(Output::efficiency), *b.u(Output::efficiency), 1e-15);
}

TEST(Uncertainty, ShaftPowerAndEfficiencyFromTorqueSpeedAndFriction) {
  Point p;
  auto cfg = zero_config();
  cfg.torque_gain_u_pct = 1.0;       // 0.025 N m
  cfg.load_b1_u_Nms_per_rad = 5e-5;  // x w^2
  p.w.batch_speed_meas_rpm = {699, 701, 699, 701};  // u = 0.57735 rpm
  const auto b = point_budget(p.in, cfg);
  const double wm = 700 * 2 * kPi / 60;
  const double u_T = 0.025 * wm, u_b1 = 5e-5 * wm * wm;
  const double u_n = std::sqrt(4.0 / 3.0) / 2.0 * (2.5 + 2 * 2e-4 * wm) * 2 * kPi / 60;
  ASSERT_TRUE(b.u(Output::pm_W));
  EXPECT_NEAR(*b.u(Output::pm_W), std::sqrt(u_T * u_T + u_b1 * u_b1 + u_n * u_n), 1e-9);
  EXPECT_NEAR(*b.u_repeat(Output::pm_W), u_n, 1e-9);  // gains and B1G are systematic
  const double u_pdcm = 420 / (std::sqrt(6.0) * 100e3);
  const double eff = p.in.pm_W / 210;
  EXPECT_NEAR(*b.u(Output::efficiency),
              std::sqrt(std::pow(*b.u(Output::pm_W) / 210, 2) + std::pow(eff * u_pdcm / 210, 2)), 1e-12);
}

TEST(Uncertainty, UdcAndSensorGainsAreSystematicAndEnterBothPowers) {
  Point p;
  auto cfg = zero_config();
  cfg.udc_gain_u_pct = 0.5;  // 2.1 V
  cfg.im_gain_u_pct = 1.0;   // 20 mA
  const auto b = point_budget(p.in, cfg);
  const double q = 420 / (std::sqrt(6.0) * 100e3);
  EXPECT_NEAR(*b.u(Output::pdcm_W), std::hypot(2.1 * 0.5, q), 1e-9);
  EXPECT_NEAR(*b.u(Output::pdcg_W), std::hypot(2.1 * 0.2, q), 1e-9);
  EXPECT_NEAR(*b.u_repeat(Output::pdcm_W), q, 1e-12);
  EXPECT_NEAR(*b.u(Output::im_A), 0.02, 1e-12);
  EXPECT_NEAR(*b.u_repeat(Output::im_A), 0.0, 1e-12);
}

TEST(Uncertainty, WithoutBatchesTheUncertaintiesThatNeedThemAreNullAndSaySo) {
  Point p;
  p.m.batch_counts_m.clear();
  p.lw.batch_torque_Nm = {2.5};  // one batch: no scatter to judge
  const auto b = point_budget(p.in, drivers::UncertaintyConfig{});
  EXPECT_FALSE(b.u(Output::pdcm_W));
  EXPECT_FALSE(b.u_repeat(Output::pdcm_W));
  EXPECT_FALSE(b.u(Output::pm_W));
  EXPECT_FALSE(b.u(Output::efficiency));
  EXPECT_FALSE(b.u_repeat(Output::efficiency));
  EXPECT_TRUE(b.u(Output::pdcg_W));  // its own batches are there
  EXPECT_TRUE(b.u(Output::im_A));
  const auto j = to_json(b);
  EXPECT_TRUE(j["combined"]["pdcm_W"].is_null());
  bool said = false;
  for (const auto& n : b.notes) said = said || n.find("I_dcM type A unavailable: the meter reports no batch means") == 0;
  EXPECT_TRUE(said);
  EXPECT_NE(to_text(b).find("I_dcM type A unavailable"), std::string::npos);
}

TEST(Uncertainty, APowerMetersPowersTakeItsAccuracyAndNoVfcComponents) {
  Point p;
  p.in.power_meter = true;
  p.in.meter = nullptr;
  const auto b = point_budget(p.in, drivers::UncertaintyConfig{});
  for (const auto& c : b.components) EXPECT_EQ(c.name.find("VFC"), std::string::npos) << c.name;
  EXPECT_FALSE(b.u(Output::pdcm_W));  // a vendor meter without batch signals: no type A
  ASSERT_TRUE(find(b, "power meter P_dcM").u);
  EXPECT_NEAR(*find(b, "power meter P_dcM").u, 210 * 0.001, 1e-12);
  EXPECT_TRUE(b.u(Output::pm_W));
}

TEST(Uncertainty, TheJsonAndTextBudgetCarryEveryComponent) {
  Point p;
  const auto b = point_budget(p.in, drivers::UncertaintyConfig{});
  const auto j = to_json(b);
  ASSERT_EQ(j["components"].size(), b.components.size());
  const auto& first = j["components"][0];
  EXPECT_EQ(first["name"], "I_dcM type A");
  EXPECT_EQ(first["type"], "A");
  EXPECT_TRUE(first["sensitivity"].contains("pdcm_W"));
  EXPECT_TRUE(first["contribution"].contains("efficiency"));
  EXPECT_DOUBLE_EQ(j["combined"]["pdcm_W"].get<double>(), *b.u(Output::pdcm_W));
  const std::string t = to_text(b);
  for (const auto& c : b.components) EXPECT_NE(t.find(c.name), std::string::npos) << c.name;
  EXPECT_NE(t.find("combined u (k = 1)"), std::string::npos);
}

}  // namespace
}  // namespace synbench::bench
