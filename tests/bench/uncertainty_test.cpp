// Tests of the point's uncertainty budget: type A of a mean from batch means, the VFC's batch
// currents, each component's value and how it propagates (GUM 5.1.2), and null where a type A
// component is unavailable.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

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

TEST(Uncertainty, TheBatchStandardErrorIsSOverSqrtBAndNeedsTwo) {
  // mean 2.5, s = sqrt(5/3), u = s / sqrt(4).
  const std::vector<double> x{1, 2, 3, 4};
  ASSERT_TRUE(batch_standard_error(x));
  EXPECT_NEAR(*batch_standard_error(x), std::sqrt(5.0 / 3.0) / 2.0, 1e-12);
  EXPECT_FALSE(batch_standard_error(std::vector<double>{1.0}));
}

// The lag-1 estimator against values computed by hand (and by an independent script forming
// E[Q0], E[Q1] as matrix traces): Q0 = sum (x - mean)^2, Q1 = sum of neighbours' products,
// solved for gamma0, gamma1 of an MA(1) series, u^2 = (g0 + 2 g1) / B - 2 g1 / B^2.
TEST(Uncertainty, TypeAOfAMeanAllowsForALagOneCorrelationOfTheBatches) {
  // {1, 3, 2, 4}: Q0 = 5, Q1 = -1.75 -> g0 = 22/15, g1 = -0.4 (inside the clamp),
  // u^2 = (22/15 - 0.8) / 4 + 0.8 / 16 = 13/60.
  const auto a = batch_type_a(std::vector<double>{1, 3, 2, 4});
  ASSERT_TRUE(a);
  EXPECT_TRUE(a->lag1);
  EXPECT_NEAR(a->u, std::sqrt(13.0 / 60.0), 1e-12);
  EXPECT_NEAR(a->standard_error, std::sqrt(5.0 / 3.0) / 2.0, 1e-12);
  EXPECT_NEAR(a->lag1_correlation, -0.4 / (22.0 / 15.0), 1e-12);
  // {1, 2, 3, 4}: a trend, g1 = 2 > g0 / 2 = 4/3: clamped to g0 / 2, u^2 = g0 / B + g0 (B - 1) / B^2,
  // 1.0801 against s / sqrt(B) = 0.6455: positively correlated batches inflate, never shrink.
  const auto t = batch_type_a(std::vector<double>{1, 2, 3, 4});
  ASSERT_TRUE(t);
  EXPECT_NEAR(t->u, std::sqrt(8.0 / 3.0 / 4.0 + 8.0 / 3.0 * 3.0 / 16.0), 1e-12);
  EXPECT_NEAR(t->lag1_correlation, 0.5, 1e-12);
  EXPECT_GT(t->u, t->standard_error);
  // {1, -1, 1, -1, 1, -1}: alternating, g1 below -g0 / 2: clamped there (the white part zero),
  // u = sqrt(g0) / B with g0 = 27/35: a pure difference series' mean.
  const auto d = batch_type_a(std::vector<double>{1, -1, 1, -1, 1, -1});
  ASSERT_TRUE(d);
  EXPECT_NEAR(d->u, std::sqrt(27.0 / 35.0) / 6.0, 1e-12);
  EXPECT_NEAR(d->lag1_correlation, -0.5, 1e-12);
  EXPECT_NEAR(*type_a_of_mean(std::vector<double>{1, -1, 1, -1, 1, -1}), d->u, 0.0);
  // Three batches: too few for a lag-1 estimate, s / sqrt(B).
  const auto three = batch_type_a(std::vector<double>{1, 3, 2});
  ASSERT_TRUE(three);
  EXPECT_FALSE(three->lag1);
  EXPECT_NEAR(three->u, 1.0 / std::sqrt(3.0), 1e-12);
  EXPECT_DOUBLE_EQ(*type_a_of_mean(std::vector<double>{3, 3, 3, 3, 3}), 0.0);
  EXPECT_FALSE(type_a_of_mean(std::vector<double>{1.0}));
  EXPECT_FALSE(type_a_of_mean(std::vector<double>{}));
}

TEST(Uncertainty, TheRegroupingFitExtrapolatesVOfBToOneBatch) {
  // {1, 3, 2, 4}: V(4) = (5/3) / 4 = 5/12; regrouped in 2 (means 2, 3): V(2) = 0.5 / 2 = 1/4.
  // The line through them: b = (5/12 - 1/4) / 2 = 1/12, a = 1/4 - 2/12 = 1/12; u^2 = a + b = 1/6.
  EXPECT_NEAR(*regrouped_type_a(std::vector<double>{1, 3, 2, 4}), std::sqrt(1.0 / 6.0), 1e-12);
  // {1, 2, 3, 4}: regrouped means 1.5, 3.5, V(2) = 2 / 2 = 1 > V(4) = 5/12: b = -7/24 < 0, and
  // a + b = 1 + 7/24 extrapolates upward (positively correlated batches).
  EXPECT_NEAR(*regrouped_type_a(std::vector<double>{1, 2, 3, 4}), std::sqrt(1.0 + (1.0 - 5.0 / 12.0) / 2.0), 1e-12);
  // Five batches (prime): no regrouping, s / sqrt(B).
  EXPECT_NEAR(*regrouped_type_a(std::vector<double>{1, 3, 2, 4, 5}), *batch_standard_error(std::vector<double>{1, 3, 2, 4, 5}),
              1e-15);
  EXPECT_FALSE(regrouped_type_a(std::vector<double>{1.0}));
}

// One window of B = 10 batch values level + e_k - e_{k-1}, e white with SD 1: position
// differences of a bounded error, whose mean has SD sqrt(2) / B.
std::vector<double> difference_series(std::mt19937& rng, std::normal_distribution<double>& e, double level) {
  std::vector<double> x(10);
  double prev = e(rng);
  for (auto& v : x) {
    const double next = e(rng);
    v = level + next - prev;
    prev = next;
  }
  return x;
}

// Many windows of 10 batches: the RMS of the reported u against the true SD of the mean.
struct Spread {
  double rms_u, rms_se, sd_u_rel;
};
template <class Gen>
Spread over_windows(Gen&& window, int windows,
                    std::optional<double> (*estimator)(std::span<const double>) = type_a_of_mean) {
  double su2 = 0, sse2 = 0, su = 0;
  for (int i = 0; i < windows; ++i) {
    const std::vector<double> x = window();
    const double u = *estimator(x);
    const double se = *batch_standard_error(x);
    su2 += u * u;
    su += u;
    sse2 += se * se;
  }
  const double n = windows, mean_u = su / n, ms_u = su2 / n;
  return {std::sqrt(ms_u), std::sqrt(sse2 / n), std::sqrt(std::max(0.0, ms_u - mean_u * mean_u)) / std::sqrt(ms_u)};
}

TEST(Uncertainty, WhiteBatchesGiveTheStandardErrorWithinNoise) {
  std::mt19937 rng(7);
  std::normal_distribution<double> e(0.0, 1.0);
  const auto s = over_windows(
      [&] {
        std::vector<double> x(10);
        for (auto& v : x) v = e(rng);
        return x;
      },
      20000);
  // Truth 1 / sqrt(10); the estimator is unbiased in u^2 before its clamps, which lift it a
  // little for white batches (a negative g1 is clamped only below -g0 / 2, a positive one
  // never gives less than s / sqrt(B)).
  std::printf("white: RMS u %.4f, RMS s/sqrt(B) %.4f, truth %.4f, SD(u)/RMS(u) %.3f\n", s.rms_u, s.rms_se,
              1 / std::sqrt(10.0), s.sd_u_rel);
  EXPECT_NEAR(s.rms_se * std::sqrt(10.0), 1.0, 0.02);
  EXPECT_NEAR(s.rms_u * std::sqrt(10.0), 1.0, 0.10);
}

TEST(Uncertainty, ADifferenceSeriesGivesLessThanTwiceSOverB) {
  // x_k = e_k - e_{k-1}: the mean is (e_B - e_0) / B, SD sqrt(2) / B, and s ~ sqrt(2): s / B,
  // where s / sqrt(B) overstates by sqrt(B).
  std::mt19937 rng(11);
  std::normal_distribution<double> e(0.0, 1.0);
  const auto s = over_windows([&] { return difference_series(rng, e, 0.0); }, 20000);
  const double truth = std::sqrt(2.0) / 10;
  std::printf("difference: RMS u %.4f, RMS s/sqrt(B) %.4f, truth %.4f, SD(u)/RMS(u) %.3f\n", s.rms_u, s.rms_se, truth,
              s.sd_u_rel);
  // The white part is zero here and its estimate, g0 + 2 g1, unbiased but noisy from 10 batches:
  // clamped at zero it is left positive about half the time, so u is conservative by about
  // 1.8 (measured) where the plain estimate overstates by sqrt(10); never optimistic.
  EXPECT_GT(s.rms_u / truth, 1.0);
  EXPECT_LT(s.rms_u / truth, 2.0);
  EXPECT_GT(s.rms_se / truth, 3.0);  // the plain estimate: about sqrt(10) too large
}

TEST(Uncertainty, WhitePlusDifferenceComesCloseToTheMeansTrueSd) {
  // The DC power's character: a white part and a larger difference part, sw^2 / tau = 1 and
  // 2 vE / tau^2 = 18: the mean's variance 1 / 10 + 18 / 100 = 0.28, where s^2 / B is 1.9.
  std::mt19937 rng(13);
  std::normal_distribution<double> e(0.0, 1.0);
  const auto s = over_windows(
      [&] {
        std::vector<double> x(10);
        double prev = 3 * e(rng);
        for (auto& v : x) {
          const double next = 3 * e(rng);
          v = e(rng) + next - prev;
          prev = next;
        }
        return x;
      },
      20000);
  const double truth = std::sqrt(0.28);
  std::printf("white + difference: RMS u %.4f, RMS s/sqrt(B) %.4f, truth %.4f, SD(u)/RMS(u) %.3f\n", s.rms_u,
              s.rms_se, truth, s.sd_u_rel);
  // As above, the zero-clamped noise of the white part's estimate: conservative by about 1.55.
  EXPECT_GT(s.rms_u / truth, 1.0);
  EXPECT_LT(s.rms_u / truth, 1.7);
  EXPECT_GT(s.rms_se / truth, 2.5);
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
  // I_dcM batches 0.49, 0.51, 0.49, 0.51 A: alternating, the lag-1 clamp at -g0 / 2 gives
  // u = sqrt(g0) / B with g0 = 8/15 x 0.01^2 (by hand as in the test above): 1.826 mA.
  p.m.batch_counts_m = {137250, 137750, 137250, 137750};
  const auto b = point_budget(p.in, zero_config());
  const auto& a = find(b, "I_dcM type A");
  ASSERT_TRUE(a.u);
  const double u_a = 0.01 * std::sqrt(8.0 / 15.0) / 4.0;
  EXPECT_NEAR(*a.u, u_a, 1e-9);
  EXPECT_EQ(a.type, 'A');
  EXPECT_DOUBLE_EQ(a.sensitivity[static_cast<std::size_t>(Output::pdcm_W)], 420);
  const double q = 1.0 / (std::sqrt(6.0) * 100e3);
  EXPECT_NEAR(*b.u(Output::pdcm_W), 420 * std::hypot(u_a, q), 1e-9);
  // efficiency = P_m / P_dcM: u(eff) = eff x u(P_dcM) / P_dcM with P_m exact here.
  EXPECT_NEAR(*b.u(Output::efficiency), p.in.pm_W / 210 * *b.u(Output::pdcm_W) / 210, 1e-12);
  EXPECT_NEAR(*b.u_repeat(Output::efficiency), *b.u(Output::efficiency), 1e-15);
}

TEST(Uncertainty, TheEncoderSpeedsTypeAIsThePositionErrorAtTheWindowsEnds) {
  // Hand-computed: B = 4, deviations -1, +1, -1, +1: running sums -1, 0, -1, so var(e) =
  // (2 / 3) / (1 + 7 / 12) = 8 / 19 and u = sqrt(2 x 8 / 19) / 4.
  const std::vector<double> alternating{699, 701, 699, 701};
  ASSERT_TRUE(position_bridge_type_a(alternating));
  EXPECT_NEAR(*position_bridge_type_a(alternating), std::sqrt(16.0 / 19.0) / 4.0, 1e-12);
  EXPECT_FALSE(position_bridge_type_a(std::vector<double>{700, 701}));
  EXPECT_EQ(*position_bridge_type_a(std::vector<double>(10, 700.0)), 0.0);
  // Speeds that are position differences of a bounded error e (independent at the batch ends,
  // SD 1 count-equivalent): the window mean's SD is sqrt(2) / B; the bridge finds it, where
  // s / sqrt(B) overstates by about sqrt(B).
  std::mt19937 rng(17);
  std::normal_distribution<double> e(0.0, 1.0);
  const auto s = over_windows([&] { return difference_series(rng, e, 700.0); }, 20000, position_bridge_type_a);
  const double truth = std::sqrt(2.0) / 10;
  std::printf("bridge: RMS u %.4f, RMS s/sqrt(B) %.4f, truth %.4f, SD(u)/RMS(u) %.3f\n", s.rms_u, s.rms_se, truth,
              s.sd_u_rel);
  EXPECT_NEAR(s.rms_u / truth, 1.0, 0.05);
  EXPECT_GT(s.rms_se / truth, 3.0);
}

TEST(Uncertainty, ShaftPowerAndEfficiencyFromTorqueSpeedAndFriction) {
  Point p;
  auto cfg = zero_config();
  cfg.torque_gain_u_pct = 1.0;       // 0.025 N m
  cfg.load_b1_u_Nms_per_rad = 5e-5;  // x w^2
  // A device window's speed: the position bridge. Running sums -1, 0, -1 (k = 1..3): var(e) =
  // (2 / 3) / (1 + 7 / 12) = 8 / 19, u = sqrt(16 / 19) / 4 = 0.22942 rpm.
  p.w.batch_speed_meas_rpm = {699, 701, 699, 701};
  const auto b = point_budget(p.in, cfg);
  const double wm = 700 * 2 * kPi / 60;
  const double u_T = 0.025 * wm, u_b1 = 5e-5 * wm * wm;
  const double u_n = std::sqrt(16.0 / 19.0) / 4.0 * (2.5 + 2 * 2e-4 * wm) * 2 * kPi / 60;
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
