// The EEMF observer's angle error th - th_hat from the filtered EEMF (e_g, e_d) in the estimated
// frame, two ways:
// - from its direction only (the thesis, atan2(-e_g, e_d)), taken modulo 180 deg; and
// - from the whole vector against the model's prediction [ours]: the EEMF's magnitude as well.
// Why the magnitude: the EEMF (Ld - Lq)(w i_d - p i_q) follows the rotor's d current. Above the
// MTPA angle an estimate running ahead by eps turns the current toward the q axis,
// i_d = I cos(th_i + eps), and the EEMF collapses exactly when its direction is needed most: the
// direction-only observer then loses the rotor (docs/estimators.md). Its magnitude meanwhile
// falls by w (L'd - Lq) i_q per radian, read against the model's E0 at zero error.
#pragma once

#include <algorithm>
#include <cmath>

#include "emulator/firmware/pi.hpp"

namespace synbench::emulator::firmware {

// Direction only, of the EEMF's line rather than its arrow: a q-current transient that outruns
// w i_d flips the EEMF's sign (high current angle, low speed), atan2 would read an error near
// 180 deg and the observer run away; a SynRM does not care about 180 deg. Weighted by
// |e|^2 / (|e|^2 + e0^2) so that a vanishing EEMF (no current, noise only) does not steer it.
inline double emf_line_angle_error(double eg_V, double ed_V, double floor_V) {
  const double e2 = eg_V * eg_V + ed_V * ed_V;
  return 0.5 * std::atan2(-2.0 * eg_V * ed_V, ed_V * ed_V - eg_V * eg_V) * (e2 / (e2 + floor_V * floor_V));
}

// What the model says the EEMF is on the estimated q axis at zero angle error, and how fast it
// falls as the estimate runs ahead: E(eps) = E0 - K eps, K = w (L'd - Lq) i_q.
struct EmfPrediction {
  double emf_V = 0;
  double slope_V_per_rad = 0;
};

// The error that best explains (e_g, e_d) = E(eps) (sin eps, cos eps) to first order, a
// Gauss-Newton step from eps = 0: eps = (E0 e_g - K (e_d - E0)) / (E0^2 + K^2). At a small
// current angle K is small and it is the direction's -e_g / E0; where the EEMF has collapsed it
// is the magnitude's (e_d - E0) / K. The floor fades it out when neither says anything, and the
// clamp keeps one sample from throwing the observer (it is a first-order reading).
inline double emf_vector_angle_error(double eg_V, double ed_V, const EmfPrediction& m, double floor_V,
                                     double limit_rad = 0.5) {
  const double e0 = m.emf_V, k = m.slope_V_per_rad;
  const double err = (-e0 * eg_V + k * (ed_V - e0)) / (e0 * e0 + k * k + floor_V * floor_V);
  return std::clamp(err, -limit_rad, limit_rad);
}

// Scales a prediction to the measured EEMF over a time constant, for a model that gets the
// EEMF's slope but not its level (RLS: incremental inductances, no flux offset of the saturated
// d axis): a least-squares gain <e_d E0> / <E0^2>. It removes the magnitude's steady bias and
// keeps its fast part, the collapse of a slip (about 0.1 s). 0 s: no scaling.
class EmfScale {
 public:
  void configure(double tau_s, double ts_s) {
    on_ = tau_s > 0;
    num_.configure(tau_s, ts_s);
    den_.configure(tau_s, ts_s);
  }
  EmfPrediction update(double ed_V, const EmfPrediction& m) {
    if (!on_) return m;
    const double num = num_.update(ed_V * m.emf_V), den = den_.update(m.emf_V * m.emf_V);
    // Until the prediction has been above about 1 V for a while the gain means nothing.
    const double g = den > 1.0 ? std::clamp(num / den, 0.25, 4.0) : 1.0;
    return {g * m.emf_V, g * m.slope_V_per_rad};
  }

 private:
  bool on_ = false;
  LowPass num_, den_;
};

}  // namespace synbench::emulator::firmware
