// Benchmark: wall time of one 100 us twin step, closed loop with encoder FOC, at a steady
// operating point. Target (issue "Foundation"): <= 0.5 us per step, i.e. >= 200x real time.
#include <benchmark/benchmark.h>

#include "drivers/modes.hpp"
#include "emulator/twin.hpp"

namespace {

using synbench::drivers::Pwm;
using synbench::emulator::Twin;
using synbench::emulator::TwinConfig;

void run_to_point(Twin& t, double speed, double load, double angle, Pwm pwm) {
  t.synrm_drive().set_pwm(pwm);
  t.synrm_drive().set_angle_deg(angle);
  t.synrm_drive().set_speed_rpm(speed);
  t.synrm_drive().enable(true);
  t.load_drive().enable(true);
  t.run_steps(15000);
  t.load_drive().set_torque_Nm(load);
  t.run_steps(15000);
}

void BM_TwinStep(benchmark::State& state, Pwm pwm) {
  Twin t{TwinConfig{}};
  run_to_point(t, 700, 2.5, 52, pwm);
  for (auto _ : state) t.step();
  state.counters["real_time_factor"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * t.step_s(),
                         benchmark::Counter::kIsRate);
}

BENCHMARK_CAPTURE(BM_TwinStep, encoder_capwm, Pwm::capwm);
BENCHMARK_CAPTURE(BM_TwinStep, encoder_aspwm, Pwm::aspwm);

}  // namespace

BENCHMARK_MAIN();
