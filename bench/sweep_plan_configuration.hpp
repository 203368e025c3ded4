// A drive configuration as the campaign compares them: position source and switching scheme
// (experiment.md Sec. 1). Shared by the sweep plan and the analysis.
#pragma once

#include <compare>
#include <string>

#include "drivers/modes.hpp"

namespace synbench::bench {

struct Configuration {
  drivers::Estimator estimator = drivers::Estimator::encoder;
  drivers::Pwm pwm = drivers::Pwm::capwm;
  // Ordered by the enums' order (encoder first, CAPWM before ASPWM), so listings are stable.
  auto operator<=>(const Configuration&) const = default;
};

// The thesis' reference: encoder, centre-aligned PWM, no injection (Sec. 6.3.3).
inline constexpr Configuration kReferenceConfiguration{drivers::Estimator::encoder, drivers::Pwm::capwm};

// "ekf-basic/aspwm"
inline std::string label(const Configuration& c) {
  return std::string(drivers::name(c.estimator)) + "/" + std::string(drivers::name(c.pwm));
}

}  // namespace synbench::bench
