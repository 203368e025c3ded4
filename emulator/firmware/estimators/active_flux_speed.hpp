// The rotor speed the EEMF's rotation terms use, from the turning of the active flux [ours].
//
// Why: the EEMF needs the rotor speed w in its w Lq terms and in the frame its current derivative
// is taken in. Taken from its own tracking observer, a speed error dw reads as an angle error
// c dw, c = i_delta (L'd - Lq) / |e| (about tan(th_i) / w), and the observer's speed error is
// its angle error's rate: it reads (d - c d') / (1 + c kp) instead of d. Above the MTPA angle,
// where the shaft makes an angle error grow, that slipped the observer at a third of the thesis
// grid (docs/estimators.md, "What still fails"). A speed that does not come from the observer
// breaks that loop.
//
// How: the stator flux of the voltage model, psi' = u - Rs i, in the stationary frame; its
// active flux psi - Lq i lies on the rotor's d axis whatever the d current does (Boldea's
// active flux), so its angle turns with the rotor. A pure integrator drifts with any voltage
// or Rs error and keeps the offset of its start: below `blend_rad_s` the flux is pulled to the
// model's flux at the estimated angle, psi' = u - Rs i + k (psi_model - psi). At the electrical
// frequency (100 rad/s and more where the EEMF runs) that is a small, slowly varying phase
// offset, which the speed does not see. The speed is the angle's rate low-passed over
// `speed_filter_s`.
//
// It needs the model's q flux to be the machine's: with a wrong Lq the active flux keeps a q part
// and its angle moves with every q-current change (EEMF-CONST on it lost the rotor at 68 points
// of the thesis grid instead of none). The drive uses it with the flux-map tables only
// (`estimators.eemf.lut_rotation_speed`).
#pragma once

#include <cmath>

#include "emulator/firmware/estimators/estimator.hpp"
#include "emulator/firmware/pi.hpp"

namespace synbench::emulator::firmware {

struct ActiveFluxSpeedParams {
  double ts_s = 1e-4;
  double blend_rad_s = 5.0;        // [assumed] below it the flux follows the model's
  double speed_filter_s = 0.015;   // [assumed] low-pass on the active flux angle's rate
};

class ActiveFluxSpeed {
 public:
  explicit ActiveFluxSpeed(const ActiveFluxSpeedParams& p) : p_(p) {
    speed_f_.configure(p.speed_filter_s, p.ts_s);
  }

  // The speed reported until the active flux has turned for one sample.
  void align(double omega_e_rad_s) { speed_f_.reset(omega_e_rad_s); }

  // Once per sample, stationary frame: the voltage applied over the period that just ended, the
  // current sampled now, the model's Rs, its stator flux at the estimated angle and its static
  // q inductance.
  void update(double ua_V, double ub_V, double ia_A, double ib_A, double rs_ohm,
              double psi_model_a_Wb, double psi_model_b_Wb, double lq_H) {
    if (!started_) {
      psi_a_ = psi_model_a_Wb;
      psi_b_ = psi_model_b_Wb;
    } else {
      psi_a_ += p_.ts_s * (ua_V - rs_ohm * ia_A + p_.blend_rad_s * (psi_model_a_Wb - psi_a_));
      psi_b_ += p_.ts_s * (ub_V - rs_ohm * ib_A + p_.blend_rad_s * (psi_model_b_Wb - psi_b_));
    }
    const double angle = std::atan2(psi_b_ - lq_H * ib_A, psi_a_ - lq_H * ia_A);
    // One sample turns the flux by w Ts, far less than half a turn.
    if (started_) speed_f_.update(wrap_pi(angle - angle_) / p_.ts_s);
    angle_ = angle;
    started_ = true;
  }

  double omega_e_rad_s() const { return speed_f_.value(); }

 private:
  ActiveFluxSpeedParams p_;
  LowPass speed_f_;
  double psi_a_ = 0, psi_b_ = 0, angle_ = 0;
  bool started_ = false;
};

}  // namespace synbench::emulator::firmware
