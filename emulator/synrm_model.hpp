// SynRM plant equations (physics.md 1.2 to 1.4): flux-linkage states, saturated flux maps,
// core loss as a parallel resistance Rc(speed, flux), Rs(T), electromagnetic torque.
#pragma once

#include <cmath>
#include <limits>

#include "emulator/flux_map.hpp"
#include "emulator/twin_config.hpp"

namespace synbench::emulator {

// Currents, torque and flux derivatives at one instant.
struct SynrmFlows {
  double id0 = 0, iq0 = 0;  // flux-producing currents (what the flux maps take)
  double id = 0, iq = 0;    // terminal currents = i0 + core-loss currents
  double torque_Nm = 0;
  double dpsi_d = 0, dpsi_q = 0;
  double pfe_W = 0;
};

class SynrmModel {
 public:
  explicit SynrmModel(const SynrmParams& p)
      : p_(p), d_(p.flux_d), q_(p.flux_q) {}

  const FluxAxis& d_axis() const { return d_; }
  const FluxAxis& q_axis() const { return q_; }
  int pole_pairs() const { return p_.pole_pairs; }

  double rs_ohm(double temp_C) const {
    return p_.rs_ohm * (1.0 + p_.rs_temp_coeff_per_K * (temp_C - p_.rs_ref_temp_C));
  }

  // Equivalent core-loss resistance; Steinmetz split (kh w + ke w^2)|Psi|^2 = 1.5 w^2 |Psi|^2 / Rc.
  // A measured Rc(speed, flux) map would replace this function.
  double rc_ohm(double we_rad_s, double /*psi_Wb*/) const {
    const double w = std::fabs(we_rad_s);
    if (w == 0.0) return std::numeric_limits<double>::infinity();
    return 1.5 / (p_.core_kh_Ws_per_radWb2 / w + p_.core_ke_Ws2_per_rad2Wb2);
  }

  SynrmFlows flows(double psi_d, double psi_q, double ud, double uq, double we, double rs) const {
    SynrmFlows f;
    f.id0 = d_.current(psi_d);
    f.iq0 = q_.current(psi_q);
    // we / Rc written so that standstill is finite: hysteresis behaves like Coulomb friction.
    const double g_we = (p_.core_kh_Ws_per_radWb2 * (we > 0 ? 1.0 : (we < 0 ? -1.0 : 0.0)) +
                         p_.core_ke_Ws2_per_rad2Wb2 * we) / 1.5;
    const double idc = -psi_q * g_we;
    const double iqc = psi_d * g_we;
    f.id = f.id0 + idc;
    f.iq = f.iq0 + iqc;
    f.torque_Nm = 1.5 * p_.pole_pairs * (psi_d * f.iq0 - psi_q * f.id0);
    f.dpsi_d = ud - rs * f.id + we * psi_q;
    f.dpsi_q = uq - rs * f.iq - we * psi_d;
    f.pfe_W = 1.5 * we * g_we * (psi_d * psi_d + psi_q * psi_q);
    return f;
  }

  double friction_torque_Nm(double wm) const {
    return p_.b1_Nms_per_rad * wm + p_.b2_Nms2_per_rad2 * wm * std::fabs(wm);
  }
  double friction_loss_W(double wm) const {
    return p_.b1_Nms_per_rad * wm * wm + p_.b2_Nms2_per_rad2 * std::fabs(wm * wm * wm);
  }

 private:
  SynrmParams p_;
  FluxAxis d_, q_;
};

}  // namespace synbench::emulator
