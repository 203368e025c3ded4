// A study's parameter deviation applied to the twin's PLANT (docs/study.md): the machine, its
// encoder and the power meter's converters differ from nominal while the drive firmware and its
// estimators keep the nominal model (TwinConfig::plant and the VFC channels' errors).
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "emulator/twin_config.hpp"

namespace synbench::emulator {

// Applies one deviation by its study parameter name (bench::kStudyParameterNames):
//   ld_pct, lq_pct      the plant's d / q flux map scaled by 1 + v/100 (the inductances with it)
//   rs_pct, inertia_pct the plant's R_s / SynRM rotor J scaled by 1 + v/100
//   encoder_offset_deg  the encoder mounted v electrical degrees ahead
//   meter_kf_pct        both VFC converters' true gain (1 + v/100) x what it was
//   meter_f0_ppm        both converters' true zero-current frequency f0 (1 + v 1e-6), as the
//                       input offset that gives it at the channel's present gain
// Deviations compose multiplicatively (percent) or add (offsets). The reason when the name is
// unknown or the result leaves the twin's valid range (config unchanged then).
std::optional<std::string> apply_plant_deviation(TwinConfig& config, std::string_view parameter, double value);

}  // namespace synbench::emulator
