// How fast an angle error of a sensorless observer grows through the shaft. The FOC places the
// current at th_i from the ESTIMATED d axis, so an error e puts it at th_i + e from the true one
// and the torque becomes T(th_i + e). Above the MTPA angle dT/dth_i < 0: an estimate running
// ahead lowers the torque, the rotor (torque-controlled load) falls further behind and e grows,
// e'' = a^2 e with a^2 = Pp |dT/dth_i| / J. A PI tracking observer (kp = 2 wn, ki = wn^2) closes
// s^2 + 2 wn s + wn^2 - a^2: it holds lock only while wn > a. At 3.5 N m and 76 deg on the bench
// a is about 85 rad/s (13.5 Hz), above the thesis' 5 Hz (EEMF) and 10 Hz (HFI) loops, which is
// why they lost lock at high current angles (docs/estimators.md). The observers raise their
// bandwidth to margin * a when a exceeds their own [assumed].
#pragma once

#include <algorithm>
#include <cmath>

#include "emulator/firmware/estimators/tracking_observer.hpp"
#include "emulator/firmware/pi.hpp"
#include "emulator/flux_map.hpp"
#include "emulator/twin_config.hpp"

namespace synbench::emulator::firmware {

struct ShaftStiffnessParams {
  FluxAxisParams flux_d, flux_q;  // the drive's flux maps
  int pole_pairs = 2;
  double inertia_kgm2 = 0;        // 0: off
  double margin = 1.5;            // observer wn = margin * a when that is above its own
};

class ShaftStiffness {
 public:
  explicit ShaftStiffness(const ShaftStiffnessParams& p) : p_(p), d_(p.flux_d), q_(p.flux_q) {}

  bool enabled() const { return p_.inertia_kgm2 > 0; }

  // a in rad/s (electrical) at the current vector (i_d, i_q) of the estimated frame; 0 where
  // the torque rises with the current angle (the shaft then stabilises the error).
  double growth_rate_rad_s(double id_A, double iq_A) const {
    if (!enabled()) return 0.0;
    const double im = std::hypot(id_A, iq_A);
    if (im < 1e-3) return 0.0;
    const double th = std::atan2(std::fabs(iq_A), std::fabs(id_A));
    constexpr double h = 0.01;  // rad
    const double slope = (torque_Nm(im, th + h) - torque_Nm(im, th - h)) / (2.0 * h);
    return slope >= 0 ? 0.0 : std::sqrt(p_.pole_pairs * -slope / p_.inertia_kgm2);
  }

  // The observer's natural frequency for its own one and the operating point.
  double bandwidth_rad_s(double own_rad_s, double id_A, double iq_A) const {
    return std::max(own_rad_s, p_.margin * growth_rate_rad_s(id_A, iq_A));
  }

 private:
  double torque_Nm(double im, double th) const {
    const double id = im * std::cos(th), iq = im * std::sin(th);
    return 1.5 * p_.pole_pairs * (d_.psi(id) * iq - q_.psi(iq) * id);
  }

  ShaftStiffnessParams p_;
  FluxAxis d_, q_;
};

// Retunes a tracking observer (HFI's PLL, the EEMF observer) to the operating point: every 1 ms
// its natural frequency becomes ShaftStiffness::bandwidth_rad_s at the observer-frame currents,
// smoothed over `current_filter_s` so that current noise does not modulate the loop.
class StiffnessTuner {
 public:
  StiffnessTuner(const ShaftStiffnessParams& p, double own_bandwidth_Hz, double current_filter_s,
                 double ts_s)
      : stiffness_(p), wn_own_(2.0 * 3.14159265358979323846 * own_bandwidth_Hz),
        every_(std::max(1L, std::lround(1e-3 / ts_s))) {
    id_f_.configure(current_filter_s, ts_s);
    iq_f_.configure(current_filter_s, ts_s);
  }

  // Once per sample, with the currents in the observer's frame.
  void update(TrackingObserver& observer, double id_A, double iq_A) {
    if (!stiffness_.enabled()) return;
    const double idf = id_f_.update(id_A), iqf = iq_f_.update(iq_A);
    if (step_++ % every_ == 0)
      observer.set_natural_frequency(stiffness_.bandwidth_rad_s(wn_own_, idf, iqf));
  }

 private:
  ShaftStiffness stiffness_;
  LowPass id_f_, iq_f_;
  double wn_own_;
  long every_, step_ = 0;
};

}  // namespace synbench::emulator::firmware
