// One-node thermal model of the SynRM winding (physics.md 1.5, [assumed] parameters):
// C dT/dt = P_Cu + P_Fe - (T - T_amb) / R_th.
#pragma once

#include "emulator/twin_config.hpp"

namespace synbench::emulator {

class ThermalNode {
 public:
  explicit ThermalNode(const ThermalParams& p) : p_(p), temp_C_(p.initial_C) {}
  double temp_C() const { return temp_C_; }
  void set_temp_C(double t) { temp_C_ = t; }
  void step(double loss_W, double dt_s) {
    temp_C_ += dt_s * (loss_W - (temp_C_ - p_.ambient_C) / p_.resistance_K_per_W) / p_.capacity_J_per_K;
  }

 private:
  ThermalParams p_;
  double temp_C_;
};

}  // namespace synbench::emulator
