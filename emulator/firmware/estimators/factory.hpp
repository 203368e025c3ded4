// Builds the estimator the bench selects, with the thesis configuration of physics.md Sec. 8.
#pragma once

#include <memory>
#include <system_error>

#include "drivers/modes.hpp"
#include "emulator/firmware/estimators/estimator.hpp"
#include "emulator/twin_config.hpp"

namespace synbench::emulator::firmware {

struct EstimatorChoice {
  std::unique_ptr<Estimator> estimator;  // null for the encoder
  bool needs_mcidc = false;              // runs on phase-reluctance samples
  std::error_code error;                 // errc::not_supported when not available
};

EstimatorChoice make_estimator(drivers::Estimator kind, const TwinConfig& config);

}  // namespace synbench::emulator::firmware
