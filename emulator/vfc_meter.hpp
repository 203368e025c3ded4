// VFC power meter (physics.md 4): each channel's converter runs at f = f0 + Kf (1 + gain error)
// (i + offset); a counter gated for the measurement window holds whole pulses; the meter reports
// I = (N / T_g - f0) / Kf with the nominal f0, Kf, so calibration errors and quantization show.
// The counters are also latched at each boundary of the gate's equal sub-gates (batches), whose
// counts sum to the gate's exactly: the bench's type A uncertainty of the currents.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "drivers/devices.hpp"
#include "emulator/twin_config.hpp"

namespace synbench::emulator {

class VfcMeter {
 public:
  explicit VfcMeter(const VfcParams& p) : p_(p) {}

  // Advances both converters by dt with the mean DC currents over the interval.
  void integrate(double idcm_A, double idcg_A, double dt_s) {
    phase_m_ += frequency(idcm_A, p_.motor) * dt_s;
    phase_g_ += frequency(idcg_A, p_.generator) * dt_s;
  }

  void open_gate(double now_s) {
    gate_start_s_ = now_s;
    start_m_ = std::floor(phase_m_);
    start_g_ = std::floor(phase_g_);
    batch_start_m_ = start_m_;
    batch_start_g_ = start_g_;
    batches_m_.clear();
    batches_g_.clear();
  }
  // Ends one sub-gate and starts the next (the gate's close ends the last).
  void end_batch() {
    batches_m_.push_back(static_cast<std::uint64_t>(std::floor(phase_m_) - batch_start_m_));
    batches_g_.push_back(static_cast<std::uint64_t>(std::floor(phase_g_) - batch_start_g_));
    batch_start_m_ = std::floor(phase_m_);
    batch_start_g_ = std::floor(phase_g_);
  }
  void close_gate(double now_s) {
    reading_ = {};
    reading_.counts_m = static_cast<std::uint64_t>(std::floor(phase_m_) - start_m_);
    reading_.counts_g = static_cast<std::uint64_t>(std::floor(phase_g_) - start_g_);
    if (!batches_m_.empty()) {
      end_batch();
      reading_.batch_counts_m = std::move(batches_m_);
      reading_.batch_counts_g = std::move(batches_g_);
    }
    batches_m_.clear();
    batches_g_.clear();
    reading_.f0_Hz = p_.f0_Hz;
    reading_.kf_Hz_per_A = p_.kf_Hz_per_A;
    reading_.gate_s = now_s - gate_start_s_;
    reading_.idcm_A = current(reading_.counts_m, reading_.gate_s);
    reading_.idcg_A = current(reading_.counts_g, reading_.gate_s);
  }
  const drivers::MeterReading& reading() const { return reading_; }
  // Whole pulses since power-on: what a free-running counter of each channel holds.
  double pulses_m() const { return std::floor(phase_m_); }
  double pulses_g() const { return std::floor(phase_g_); }

  double current(std::uint64_t counts, double gate_s) const {
    return (static_cast<double>(counts) / gate_s - p_.f0_Hz) / p_.kf_Hz_per_A;
  }

 private:
  double frequency(double i_A, const VfcChannelErrors& e) const {
    return std::max(0.0, p_.f0_Hz + p_.kf_Hz_per_A * (1.0 + e.gain_error) * (i_A + e.offset_error_A));
  }
  VfcParams p_;
  double phase_m_ = 0, phase_g_ = 0;  // pulses since power-on (fractional part: the converter's phase)
  double start_m_ = 0, start_g_ = 0, gate_start_s_ = 0;
  double batch_start_m_ = 0, batch_start_g_ = 0;
  std::vector<std::uint64_t> batches_m_, batches_g_;  // the sub-gates ended so far
  drivers::MeterReading reading_;
};

}  // namespace synbench::emulator
