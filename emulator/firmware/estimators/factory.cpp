// Estimator selection, with the thesis configurations of physics.md Sec. 8.
#include "emulator/firmware/estimators/factory.hpp"

#include "drivers/error.hpp"
#include "emulator/firmware/estimators/eemf.hpp"
#include "emulator/firmware/estimators/ekf_basic.hpp"
#include "emulator/firmware/estimators/ekf_rs.hpp"
#include "emulator/firmware/estimators/handover.hpp"
#include "emulator/firmware/estimators/hfi.hpp"
#include "emulator/firmware/estimators/lock_guard.hpp"

namespace synbench::emulator::firmware {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRadSPerRpm = 2.0 * kPi / 60.0;

ShaftStiffnessParams stiffness(const TwinConfig& config) {
  ShaftStiffnessParams s;
  s.flux_d = config.synrm.flux_d;
  s.flux_q = config.synrm.flux_q;
  s.pole_pairs = config.synrm.pole_pairs;
  // The drive tunes its speed loop with the same inertia.
  s.inertia_kgm2 = config.total_inertia_kgm2();
  return s;
}

std::unique_ptr<Estimator> make_hfi(const TwinConfig& config) {
  const auto& h = config.estimators.hfi;
  HfiParams p;
  p.ts_s = config.step_s();
  p.voltage_V = h.voltage_V;
  p.frequency_Hz = h.frequency_Hz;
  p.bandpass_bandwidth_Hz = h.bandpass_bandwidth_Hz;
  p.pll_bandwidth_Hz = h.pll_bandwidth_Hz;
  p.align_s = h.align_s;
  p.stiffness = stiffness(config);
  return std::make_unique<Hfi>(p);
}

std::unique_ptr<Estimator> make_eemf(const TwinConfig& config, EemfModel model) {
  const auto& e = config.estimators.eemf;
  EemfParams p;
  p.ts_s = config.step_s();
  p.model = model;
  p.rs_ohm = config.synrm.rs_ohm;
  p.ld_H = e.ld_H;
  p.lq_H = e.lq_H;
  p.flux_d = config.synrm.flux_d;
  p.flux_q = config.synrm.flux_q;
  p.lut_ld_scale = e.lut_ld_scale;
  p.lut_lq_scale = e.lut_lq_scale;
  p.observer_bandwidth_Hz = e.observer_bandwidth_Hz;
  p.stiffness = stiffness(config);
  p.stiffness.margin = e.stiffness_margin;
  p.speed_filter_s = e.speed_filter_s;
  // The active flux needs the machine's q flux: only the tables have it (active_flux_speed.hpp).
  p.rotation_speed = model == EemfModel::lut && e.lut_rotation_speed == LutRotationSpeed::active_flux
                         ? EemfRotationSpeed::active_flux
                         : EemfRotationSpeed::observer;
  // The magnitude needs a model of it: the tables have one, the RLS its slope (scaled to the
  // measurement), the constants neither (emf_angle_error.hpp).
  p.vector_error = model != EemfModel::constant && e.error_signal == EemfErrorSignal::vector;
  p.emf_scale_filter_s = model == EemfModel::rls ? e.rls_emf_scale_filter_s : 0.0;
  p.flux_speed.blend_rad_s = e.flux_blend_rad_s;
  p.flux_speed.speed_filter_s = e.flux_speed_filter_s;
  p.rls_forgetting = e.rls_forgetting;
  p.rls_p0 = e.rls_p0;
  p.rls_sample_s = e.rls_sample_s;
  p.rls_estimate_filter_s = e.rls_estimate_filter_s;
  p.rls_model_filter_s = e.rls_model_filter_s;
  p.rls_warmup_s = e.rls_warmup_s;
  p.rls_flux_offset = e.rls_flux_offset;
  p.prbs_voltage_V = e.prbs_voltage_V;
  p.prbs_bit_s = e.prbs_bit_s;
  const double w_min = e.min_speed_rpm * kRadSPerRpm * config.synrm.pole_pairs;
  const double w_hyst = e.handover_hysteresis_rpm * kRadSPerRpm * config.synrm.pole_pairs;
  return std::make_unique<LowSpeedHandover>(
      std::make_unique<Eemf>(p), e.low_speed_source == LowSpeedSource::hfi ? make_hfi(config) : nullptr, w_min,
      w_hyst, config.firmware.lock_guard_deg * kPi / 180.0, p.ts_s);
}

EstimatorChoice make_sensorless(drivers::Estimator kind, const TwinConfig& config) {
  EstimatorChoice c;
  const double ts = config.step_s();
  const double rs_threshold =
      config.estimators.ekf.rs_speed_threshold_rpm * kRadSPerRpm * config.synrm.pole_pairs;
  switch (kind) {
    case drivers::Estimator::encoder:
      return c;
    case drivers::Estimator::ekf_basic: {
      EkfBasicParams p;
      p.ts_s = ts;
      c.estimator = std::make_unique<EkfBasic>(p);
      c.needs_mcidc = true;
      return c;
    }
    case drivers::Estimator::ekf_rs: {
      EkfRsParams p;
      p.ts_s = ts;
      p.rs_speed_threshold_rad_s = rs_threshold;
      // The drive's flux maps (those of its decoupling and of EEMF-LUT) for the back-EMF terms:
      // with the thesis' linear model Rs absorbs the saturated machine's back-EMF error.
      p.flux_d = config.synrm.flux_d;
      p.flux_q = config.synrm.flux_q;
      c.estimator = std::make_unique<EkfRs>(p);
      c.needs_mcidc = true;
      return c;
    }
    case drivers::Estimator::hfi:
      c.estimator = make_hfi(config);
      return c;
    case drivers::Estimator::eemf_const:
      c.estimator = make_eemf(config, EemfModel::constant);
      return c;
    case drivers::Estimator::eemf_lut:
      c.estimator = make_eemf(config, EemfModel::lut);
      return c;
    case drivers::Estimator::eemf_rls:
      c.estimator = make_eemf(config, EemfModel::rls);
      return c;
  }
  c.error = make_error_code(errc::not_supported);
  return c;
}

}  // namespace

EstimatorChoice make_estimator(drivers::Estimator kind, const TwinConfig& config) {
  EstimatorChoice c = make_sensorless(kind, config);
  const auto& f = config.firmware;
  if (c.estimator && f.lock_guard_deg > 0) {
    auto make = [kind, config] { return make_sensorless(kind, config).estimator; };
    const double speed_rad_s = f.lock_guard_speed_rpm * kRadSPerRpm * config.synrm.pole_pairs;
    c.estimator = std::make_unique<LockGuard>(make, f.lock_guard_deg * kPi / 180.0, speed_rad_s,
                                              f.lock_guard_s, f.lock_guard_current_A, config.step_s());
  }
  return c;
}

}  // namespace synbench::emulator::firmware
