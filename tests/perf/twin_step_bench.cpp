// Benchmark: wall time of one 100 us twin step, closed loop, at a steady operating point, per
// position source, in lock (counter lock_lost = 0). Targets: encoder FOC <= 0.5 us per step
// (>= 200x real time, issue "Foundation"); EKF-RS <= 1 us, stretch 0.5 us (issue "Sensorless
// estimators").
#include <benchmark/benchmark.h>

#include "drivers/modes.hpp"
#include "emulator/twin.hpp"

namespace {

using synbench::drivers::Estimator;
using synbench::drivers::Pwm;
using synbench::emulator::Twin;
using synbench::emulator::TwinConfig;

// Spin-up and load at 45 deg, then the point's angle, as the point procedure starts a sensorless
// point (docs/record.md): loaded at a high angle from rest an EEMF loses the rotor, and the
// figure would time the lock guard's encoder instead of the estimator.
void run_to_point(Twin& t, double speed, double load, double angle, Pwm pwm, Estimator e) {
  t.synrm_drive().set_pwm(pwm);
  t.synrm_drive().set_estimator(e);
  t.synrm_drive().set_angle_deg(45);
  t.synrm_drive().set_speed_rpm(speed);
  t.synrm_drive().enable(true);
  t.load_drive().enable(true);
  t.run_steps(15000);
  t.load_drive().set_torque_Nm(load);
  t.run_steps(15000);
  t.synrm_drive().set_angle_deg(angle);
  t.run_steps(15000);
}

void BM_TwinStep(benchmark::State& state, Pwm pwm, Estimator e, double load_Nm = 2.5,
                 synbench::emulator::LutRotationSpeed lut_rotation_speed = synbench::emulator::LutRotationSpeed::observer) {
  TwinConfig cfg;
  cfg.estimators.eemf.lut_rotation_speed = lut_rotation_speed;
  Twin t{cfg};
  run_to_point(t, 700, load_Nm, 52, pwm, e);
  for (auto _ : state) t.step();
  // 1 if the estimator lost the rotor and the drive ran on the encoder: the time is then not
  // the estimator's.
  state.counters["lock_lost"] = t.synrm_drive().telemetry().lock_lost ? 1 : 0;
  state.counters["real_time_factor"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * t.step_s(),
                         benchmark::Counter::kIsRate);
}

BENCHMARK_CAPTURE(BM_TwinStep, encoder_capwm, Pwm::capwm, Estimator::encoder);
BENCHMARK_CAPTURE(BM_TwinStep, encoder_aspwm, Pwm::aspwm, Estimator::encoder);
BENCHMARK_CAPTURE(BM_TwinStep, ekf_basic_aspwm, Pwm::aspwm, Estimator::ekf_basic);
BENCHMARK_CAPTURE(BM_TwinStep, ekf_rs_aspwm, Pwm::aspwm, Estimator::ekf_rs);
BENCHMARK_CAPTURE(BM_TwinStep, hfi_capwm, Pwm::capwm, Estimator::hfi);
BENCHMARK_CAPTURE(BM_TwinStep, eemf_lut_capwm, Pwm::capwm, Estimator::eemf_lut);
BENCHMARK_CAPTURE(BM_TwinStep, eemf_lut_active_flux_capwm, Pwm::capwm, Estimator::eemf_lut, 2.5,
                  synbench::emulator::LutRotationSpeed::active_flux);
// EEMF-RLS holds the rotor at light load only (docs/estimators.md).
BENCHMARK_CAPTURE(BM_TwinStep, eemf_rls_capwm_0_5Nm, Pwm::capwm, Estimator::eemf_rls, 0.5);

}  // namespace

BENCHMARK_MAIN();
