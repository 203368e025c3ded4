// Operating modes a SynRM drive can be asked for: switching scheme and position source.
#pragma once

#include <array>
#include <optional>
#include <string_view>

namespace synbench::drivers {

enum class Pwm { capwm = 0, aspwm = 1 };

enum class Estimator { encoder = 0, ekf_basic, ekf_rs, hfi, eemf_const, eemf_lut, eemf_rls };

inline constexpr std::array<std::string_view, 2> kPwmNames{"capwm", "aspwm"};
inline constexpr std::array<std::string_view, 7> kEstimatorNames{
    "encoder", "ekf-basic", "ekf-rs", "hfi", "eemf-const", "eemf-lut", "eemf-rls"};

constexpr std::string_view name(Pwm p) { return kPwmNames[static_cast<std::size_t>(p)]; }
constexpr std::string_view name(Estimator e) { return kEstimatorNames[static_cast<std::size_t>(e)]; }

inline std::optional<Pwm> parse_pwm(std::string_view s) {
  for (std::size_t i = 0; i < kPwmNames.size(); ++i)
    if (kPwmNames[i] == s) return static_cast<Pwm>(i);
  return std::nullopt;
}

inline std::optional<Estimator> parse_estimator(std::string_view s) {
  for (std::size_t i = 0; i < kEstimatorNames.size(); ++i)
    if (kEstimatorNames[i] == s) return static_cast<Estimator>(i);
  return std::nullopt;
}

}  // namespace synbench::drivers
