// Phase-reluctance measurement from the DC-link current slope (MCIDC, physics.md 6, thesis 5.1).
// The slope sees the dynamic inductances at the operating point; the sample carries white noise,
// a gain error and a periodic deformation. ASPWM measures one phase per period (a, b, c in turn);
// CAPWM measures the phase with the longer active vector, and nothing when it is too short; with
// the modulator's window shift (an MCIDC estimator selected) it too measures a, b, c in turn.
#pragma once

#include <cmath>
#include <optional>

#include "drivers/modes.hpp"
#include "emulator/inverter_model.hpp"
#include "emulator/noise.hpp"
#include "emulator/twin_config.hpp"

namespace synbench::emulator {

struct McidcSample {
  int phase = 0;               // 0 = a, 1 = b, 2 = c
  double reluctance_per_H = 0; // measured normalized phase reluctance R'_phN
};

inline constexpr double kPhaseOffsetRad[3] = {0.0, -2.0943951023931953, 2.0943951023931953};

// True normalized reluctance of phase `n` (5.5 to 5.12) from the d and q inductances.
inline double phase_reluctance(double theta_e, int n, double ld_H, double lq_H) {
  const double c = std::cos(theta_e + kPhaseOffsetRad[n]);
  const double c2 = c * c;
  return c2 / ld_H + (1.0 - c2) / lq_H;
}

class Mcidc {
 public:
  Mcidc(const McidcParams& p, double pwm_period_s) : p_(p), ts_(pwm_period_s) {}

  std::optional<McidcSample> measure(std::uint64_t step, drivers::Pwm pwm, const Phases& duty,
                                     double theta_e, double ld_dyn_H, double lq_dyn_H,
                                     Noise& noise, bool window_shift = false) const {
    int phase;
    if (pwm == drivers::Pwm::aspwm || window_shift) {
      // ASPWM, or CAPWM with the window shift: one phase per period, a, b, c in turn. The
      // natural CAPWM choice (the phase with the longer active vector) follows the voltage
      // vector, which at speed lies near the q axis, where R'_ph barely depends on the angle:
      // fed those samples EKF-BASIC lost lock at 500 rpm. Shifting the chosen leg's pulse
      // by the minimum active time against the other two (same duty, same edges) opens a
      // window in which only that leg differs, whatever the duties.
      phase = static_cast<int>(step % 3);
    } else {
      int hi = 0, lo = 0;
      for (int n = 1; n < 3; ++n) {
        if (duty[n] > duty[hi]) hi = n;
        if (duty[n] < duty[lo]) lo = n;
      }
      const int mid = 3 - hi - lo;
      const double t_hi = (duty[hi] - duty[mid]) * ts_, t_lo = (duty[mid] - duty[lo]) * ts_;
      phase = t_hi >= t_lo ? hi : lo;
      if (std::max(t_hi, t_lo) < p_.min_active_time_s) return std::nullopt;
    }
    const double x = theta_e + kPhaseOffsetRad[phase];
    const double truth = phase_reluctance(theta_e, phase, ld_dyn_H, lq_dyn_H);
    const double deformation = p_.deformation_amplitude_per_H * std::cos(p_.deformation_harmonic * x);
    return McidcSample{phase, truth * (1.0 + p_.gain_error) + deformation +
                                  p_.noise_sigma_per_H * noise.gauss()};
  }

 private:
  McidcParams p_;
  double ts_;
};

}  // namespace synbench::emulator
