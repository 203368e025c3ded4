// Saturated flux linkage of one SynRM axis (thesis 1.22, Table 1.2), no cross-saturation.
// The switch point is the upper crossing of the linear and saturated branches (physics.md 1.1),
// which keeps Psi continuous and monotonic; the published thresholds are not used.
#pragma once

#include <cmath>

#include "emulator/twin_config.hpp"

namespace synbench::emulator {

class FluxAxis {
 public:
  explicit FluxAxis(const FluxAxisParams& p)
      : l0_(p.l0_H), psi0_(p.psi0_Wb), l1_(p.l1_H), beta_(p.beta_WbA) {
    const double a = l0_ - l1_;
    i_switch_ = (psi0_ + std::sqrt(psi0_ * psi0_ + 4.0 * a * beta_)) / (2.0 * a);
    psi_switch_ = l0_ * i_switch_;
  }

  double switch_current_A() const { return i_switch_; }

  double psi(double i) const {
    const double a = std::fabs(i);
    if (a <= i_switch_) return l0_ * i;
    return std::copysign(psi0_ + l1_ * a + beta_ / a, i);
  }

  // Inverse map: the flux-producing current that gives flux `psi`.
  double current(double psi) const {
    const double a = std::fabs(psi);
    if (a <= psi_switch_) return psi / l0_;
    const double x = a - psi0_;
    return std::copysign((x + std::sqrt(x * x - 4.0 * l1_ * beta_)) / (2.0 * l1_), psi);
  }

  // Static inductance Psi/i (1.23, 1.24); L0 at zero current.
  double static_inductance_H(double i) const {
    return std::fabs(i) <= i_switch_ ? l0_ : psi(i) / i;
  }

  // Dynamic inductance dPsi/di (1.25, 1.26).
  double dynamic_inductance_H(double i) const {
    const double a = std::fabs(i);
    return a <= i_switch_ ? l0_ : l1_ - beta_ / (a * a);
  }

 private:
  double l0_, psi0_, l1_, beta_;
  double i_switch_ = 0, psi_switch_ = 0;
};

}  // namespace synbench::emulator
