// Shared DC bus (physics.md 3): rectified source behind a resistance (diodes: it only sources),
// bus capacitance, brake chopper with hysteresis. U_dc is a state.
#pragma once

#include <algorithm>

#include "emulator/twin_config.hpp"

namespace synbench::emulator {

class DcBus {
 public:
  explicit DcBus(const DcBusParams& p) : p_(p), u_V_(p.source_V) {}

  double voltage_V() const { return u_V_; }
  bool brake_on() const { return brake_on_; }

  // dU/dt for a net load current `i_load_A` (inverter inputs minus returns); `surge_V` raises
  // the source (a fault hook).
  double derivative(double u_V, double i_load_A, double surge_V = 0.0) const {
    const double i_src = std::max(0.0, (p_.source_V + surge_V - u_V) / p_.source_ohm);
    const double i_brake = brake_on_ ? u_V / p_.brake_ohm : 0.0;
    return (i_src - i_load_A - i_brake) / p_.capacitance_F;
  }

  void set_voltage(double u_V) {
    u_V_ = u_V;
    if (u_V_ > p_.brake_on_V) brake_on_ = true;
    if (u_V_ < p_.brake_off_V) brake_on_ = false;
  }

 private:
  DcBusParams p_;
  double u_V_;
  bool brake_on_ = false;
};

}  // namespace synbench::emulator
