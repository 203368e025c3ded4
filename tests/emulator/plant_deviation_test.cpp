// A study's deviations reach the twin's plant and only the plant: the drive firmware and its
// estimators keep the nominal model.
#include "emulator/plant_deviation.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "bench/study_plan.hpp"
#include "emulator/flux_map.hpp"
#include "emulator/twin.hpp"
#include "emulator/twin_config_schema.hpp"
#include "point_runner.hpp"

namespace synbench::emulator {
namespace {

TEST(PlantDeviation, EveryStudyParameterApplies) {
  for (auto name : bench::kStudyParameterNames) {
    TwinConfig c;
    EXPECT_FALSE(apply_plant_deviation(c, name, 10)) << name;
  }
  TwinConfig c;
  EXPECT_NE(apply_plant_deviation(c, "lx_pct", 1)->find("unknown plant parameter"), std::string::npos);
}

TEST(PlantDeviation, FluxResistanceAndInertiaScaleThePlantNotTheModel) {
  TwinConfig c;
  ASSERT_FALSE(apply_plant_deviation(c, "ld_pct", 25));
  ASSERT_FALSE(apply_plant_deviation(c, "ld_pct", -20));  // composes: 1.25 x 0.8 = 1
  EXPECT_NEAR(c.plant.flux_d_scale, 1.0, 1e-12);
  ASSERT_FALSE(apply_plant_deviation(c, "lq_pct", -25));
  ASSERT_FALSE(apply_plant_deviation(c, "rs_pct", 10));
  ASSERT_FALSE(apply_plant_deviation(c, "inertia_pct", 50));
  const TwinConfig nominal;
  // The model the firmware gets is untouched.
  EXPECT_EQ(c.synrm.flux_q.l0_H, nominal.synrm.flux_q.l0_H);
  EXPECT_EQ(c.synrm.rs_ohm, nominal.synrm.rs_ohm);
  // The plant's: Psi_q scaled at every current, through the knee.
  const FluxAxis plant_q(c.plant_synrm().flux_q), model_q(nominal.synrm.flux_q);
  for (double i : {0.3, 1.0, 2.5, 4.0}) EXPECT_NEAR(plant_q.psi(i), 0.75 * model_q.psi(i), 1e-12) << i;
  EXPECT_NEAR(c.plant_synrm().rs_ohm, 1.1 * nominal.synrm.rs_ohm, 1e-12);
  EXPECT_NEAR(c.plant_synrm().inertia_kgm2, 1.5 * nominal.synrm.inertia_kgm2, 1e-15);
  // The twin simulates the plant's.
  const Twin twin(c);
  EXPECT_NEAR(twin.synrm_model().q_axis().psi(1.0), 0.75 * model_q.psi(1.0), 1e-12);
  // And the config file carries it (a deviated twin can be given to `synbench sweep --config`).
  TwinConfig back;
  apply_json(back, to_json(c));
  EXPECT_EQ(back.plant.flux_q_scale, c.plant.flux_q_scale);
}

TEST(PlantDeviation, OutOfRangeIsRefusedAndLeavesTheConfig) {
  TwinConfig c;
  const auto e = apply_plant_deviation(c, "ld_pct", -90);  // scale 0.1 < 0.2
  ASSERT_TRUE(e);
  EXPECT_NE(e->find("/plant/flux_d_scale"), std::string::npos) << *e;
  EXPECT_EQ(c.plant.flux_d_scale, 1.0);
}

TEST(PlantDeviation, MeterCalibrationShowsInTheReading) {
  TwinConfig c;
  ASSERT_FALSE(apply_plant_deviation(c, "meter_kf_pct", 2));
  ASSERT_FALSE(apply_plant_deviation(c, "meter_f0_ppm", 100));
  VfcMeter nominal(TwinConfig{}.vfc), deviated(c.vfc);
  for (VfcMeter* m : {&nominal, &deviated}) {
    m->open_gate(0);
    m->integrate(1.5, 1.2, 1.0);
    m->close_gate(1.0);
  }
  // I = 1.02 (1.5 + offset) with offset = f0 1e-4 / (Kf 1.02): 1.53 + 5e-4, within a count.
  const double offset_A = TwinConfig{}.vfc.f0_Hz * 100e-6 / TwinConfig{}.vfc.kf_Hz_per_A;
  EXPECT_NEAR(deviated.reading().idcm_A, 1.02 * 1.5 + offset_A, 2e-5);
  EXPECT_NEAR(nominal.reading().idcm_A, 1.5, 2e-5);
}

// An encoder mounted 10 electrical degrees ahead: an estimator that tracks the true rotor reads
// 10 deg behind the encoder. EKF-BASIC at 700 rpm, 1 N m.
TEST(PlantDeviation, EncoderOffsetShowsInThePositionError) {
  bench::PointRequest req;
  req.speed_rpm = 700;
  req.load_Nm = 1.0;
  req.angle_deg = 56;
  req.estimator = drivers::Estimator::ekf_basic;
  req.pwm = drivers::Pwm::aspwm;
  req.window_s = 0.5;
  const auto nominal = testing::measure(TwinConfig{}, req);
  TwinConfig c;
  ASSERT_FALSE(apply_plant_deviation(c, "encoder_offset_deg", 10));
  const auto offset = testing::measure(c, req);
  ASSERT_TRUE(nominal.pos_err_mean_deg && offset.pos_err_mean_deg);
  EXPECT_NEAR(*offset.pos_err_mean_deg - *nominal.pos_err_mean_deg, -10.0, 1.0)
      << "nominal " << *nominal.pos_err_mean_deg << ", offset " << *offset.pos_err_mean_deg;
}

}  // namespace
}  // namespace synbench::emulator
