// Interface of a position/speed/parameter estimator running in the SynRM drive firmware
// (physics.md 8). The firmware calls update() once per PWM period with what its sensors saw;
// the selected estimator's angle and speed then drive the FOC (the encoder is only the reference).
#pragma once

#include <cmath>
#include <optional>

namespace synbench::emulator::firmware {

// An angle wrapped to (-pi, pi]. Cheap for the usual case, an angle at most one turn out.
inline double wrap_pi(double a) {
  constexpr double pi = 3.14159265358979323846;
  if (a > -pi && a <= pi) return a;
  if (a > pi && a <= 3.0 * pi) return a - 2.0 * pi;
  if (a <= -pi && a > -3.0 * pi) return a + 2.0 * pi;
  a = std::remainder(a, 2.0 * pi);  // [-pi, pi]
  return a <= -pi ? a + 2.0 * pi : a;
}

// A position error wrapped to (-pi/2, pi/2]: a SynRM's reluctance repeats every half electrical
// turn, so an estimate half a turn off is as good as the encoder's.
inline double half_turn_error_rad(double err_rad) {
  constexpr double kHalfTurn = 3.14159265358979323846;
  const double e = std::remainder(err_rad, kHalfTurn);
  return e <= -kHalfTurn / 2 ? e + kHalfTurn : e;
}

struct EstimatorInput {
  double ts_s = 1e-4;
  double ialpha_A = 0, ibeta_A = 0;  // measured phase currents, stationary frame
  double ualpha_V = 0, ubeta_V = 0;  // voltage applied during the period that just ended
  // One MCIDC sample of this period: phase index (0 a, 1 b, 2 c) and R'_ph in 1/H.
  std::optional<int> mcidc_phase;
  double mcidc_reluctance_per_H = 0;
  // The encoder's angle and speed: only for a handover to the encoder below an estimator's
  // minimum speed (the thesis ran EEMF on the encoder there) and for the drive's lock guard;
  // estimators must not use them.
  double encoder_theta_e_rad = 0, encoder_omega_e_rad_s = 0;
};

struct EstimatorOutput {
  double theta_e_rad = 0;    // estimated electrical angle
  double omega_e_rad_s = 0;  // estimated electrical speed
  std::optional<double> ld_H, lq_H, rs_ohm;
};

class Estimator {
 public:
  virtual ~Estimator() = default;
  virtual void update(const EstimatorInput& in) = 0;
  virtual EstimatorOutput output() const = 0;
  // Voltage the estimator adds to the current controllers' output this period, in the estimated
  // d, q frame (HFI carrier, PRBS excitation). None by default.
  virtual void injection(double& ud_V, double& uq_V) const {
    ud_V = 0;
    uq_V = 0;
  }
  // The currents, in the estimated frame, the current controllers should regulate: an injecting
  // estimator removes its own high-frequency response. Unchanged by default.
  virtual void fundamental(double& /*id_A*/, double& /*iq_A*/) const {}
  // True while the estimator must find the rotor before the drive may apply torque current
  // (HFI's initial position detection after an enable): the drive runs the gates and the
  // injection with the speed loop held at zero current until it ends.
  virtual bool aligning() const { return false; }
  // True while a low-speed fallback, not this estimator, gives the angle (LowSpeedHandover below
  // its minimum speed): the measurement window counts those samples.
  virtual bool on_fallback() const { return false; }
  // True once the estimator's own speed has been seen falling away from the shaft's (a low-speed
  // handover gave the angle back to the encoder while the shaft still turned above the take-over
  // speed and the estimator's angle had left the shaft's): the drive's lock guard counts it as a
  // lost rotor.
  virtual bool slipped() const { return false; }
  // True while this period's angle is the encoder's (a low-speed handover to the encoder, the
  // lock guard): a position or speed error against the encoder then measures nothing.
  virtual bool encoder_angle() const { return false; }
  // Takes over the given angle and speed (a handover from another position source).
  virtual void align(double /*theta_e_rad*/, double /*omega_e_rad_s*/) {}
  // True while the drive's lock guard has taken the angle from the encoder (LockGuard); rearm()
  // hands it back to the estimator at the next operating point.
  virtual bool lock_lost() const { return false; }
  virtual void rearm() {}
};

}  // namespace synbench::emulator::firmware
