// Two-level three-phase inverter, PWM-averaged (physics.md 5): SVM duty cycles and its linear
// voltage limit, dead-time voltage error, conduction (3.6) and switching (3.7) losses for the
// CAPWM and ASPWM schemes.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

#include "drivers/modes.hpp"
#include "emulator/twin_config.hpp"

namespace synbench::emulator {

using Phases = std::array<double, 3>;

inline constexpr double kSqrt3 = 1.7320508075688772;

// Amplitude-invariant inverse Clarke (physics.md 0).
inline Phases to_phases(double a, double b) {
  return {a, -0.5 * a + 0.5 * kSqrt3 * b, -0.5 * a - 0.5 * kSqrt3 * b};
}
inline void to_alpha_beta(const Phases& x, double& a, double& b) {
  a = (2.0 / 3.0) * (x[0] - 0.5 * x[1] - 0.5 * x[2]);
  b = (x[1] - x[2]) / kSqrt3;
}

// Gate edges per PWM period: CAPWM switches every leg twice, ASPWM (Sec. 5.2) saves a third.
constexpr int edges_per_period(drivers::Pwm p) { return p == drivers::Pwm::capwm ? 12 : 8; }

class InverterModel {
 public:
  explicit InverterModel(const InverterParams& p) : p_(p), ts_(1.0 / p.pwm_frequency_Hz) {}

  // Largest phase-voltage amplitude SVM produces without overmodulation.
  static double voltage_limit_V(double udc_V) { return udc_V / kSqrt3; }

  // Leg duty cycles for a phase-voltage vector, min-max zero sequence (equivalent to SVM).
  static Phases duties(double ua, double ub, double udc_V) {
    Phases u = to_phases(ua, ub);
    const double hi = std::max({u[0], u[1], u[2]}), lo = std::min({u[0], u[1], u[2]});
    const double zero = -0.5 * (hi + lo);
    for (auto& x : u) x = std::clamp(0.5 + (x + zero) / udc_V, 0.0, 1.0);
    return u;
  }

  // Dead-time error of each phase voltage: the dead time takes U_dc t_d / T_pwm off the phase in
  // the direction of its current, fading linearly inside a small current band.
  double dead_time_error_V(double i_A, double udc_V) const {
    const double s = std::clamp(i_A / p_.dead_time_current_band_A, -1.0, 1.0);
    return -s * udc_V * p_.dead_time_s / ts_;
  }

  // Conduction and switching loss of the three legs for phase currents `i` and leg duties `d`.
  double loss_W(const Phases& i, const Phases& d, double udc_V, drivers::Pwm pwm) const {
    // Switching events per leg and period: 12 edges -> 2 per leg (CAPWM), 8 -> 4/3 (ASPWM).
    const double k_sw = edges_per_period(pwm) / 6.0;
    const double e_scale = udc_V / p_.esw_ref_V;
    double loss = 0;
    for (int n = 0; n < 3; ++n) {
      const double a = std::fabs(i[n]);
      const double dt = i[n] > 0 ? d[n] : 1.0 - d[n];  // share of the period in the IGBT
      const double vce = p_.vce0_V + p_.rce_ohm * a, vf = p_.vf0_V + p_.rf_ohm * a;
      loss += dt * a * vce + (1.0 - dt) * a * vf;
      loss += k_sw / ts_ * (p_.esw0_J + p_.esw_per_A_J * a) * e_scale;
    }
    return loss;
  }

  const InverterParams& params() const { return p_; }

 private:
  InverterParams p_;
  double ts_;
};

}  // namespace synbench::emulator
