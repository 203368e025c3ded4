// A study's deviation on the twin's plant; see plant_deviation.hpp.
#include "emulator/plant_deviation.hpp"

#include "emulator/twin_config_schema.hpp"

namespace synbench::emulator {

std::optional<std::string> apply_plant_deviation(TwinConfig& config, std::string_view parameter, double value) {
  TwinConfig c = config;
  const double factor = 1.0 + value / 100.0;
  if (parameter == "ld_pct") {
    c.plant.flux_d_scale *= factor;
  } else if (parameter == "lq_pct") {
    c.plant.flux_q_scale *= factor;
  } else if (parameter == "rs_pct") {
    c.plant.rs_scale *= factor;
  } else if (parameter == "inertia_pct") {
    c.plant.inertia_scale *= factor;
  } else if (parameter == "encoder_offset_deg") {
    c.plant.encoder_offset_deg += value;
  } else if (parameter == "meter_kf_pct") {
    for (VfcChannelErrors* ch : {&c.vfc.motor, &c.vfc.generator}) ch->gain_error = (1.0 + ch->gain_error) * factor - 1.0;
  } else if (parameter == "meter_f0_ppm") {
    // f = f0 + Kf (1 + g) (i + offset): a true f0 off by df0 is an input offset df0 / (Kf (1 + g)).
    const double df0_Hz = c.vfc.f0_Hz * value * 1e-6;
    for (VfcChannelErrors* ch : {&c.vfc.motor, &c.vfc.generator})
      ch->offset_error_A += df0_Hz / (c.vfc.kf_Hz_per_A * (1.0 + ch->gain_error));
  } else {
    return "unknown plant parameter '" + std::string(parameter) + "'";
  }
  // The twin's own ranges: a factor that leaves them is refused here, not in the middle of a run.
  try {
    apply_json(c, to_json(c));
    validate(c);
  } catch (const ConfigError& e) {
    return std::string(parameter) + " " + std::to_string(value) + ": " + e.what();
  }
  config = c;
  return std::nullopt;
}

}  // namespace synbench::emulator
