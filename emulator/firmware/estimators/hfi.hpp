// High-frequency injection (physics.md 8, thesis 2.15 to 2.22, Sec. 6.2.2): a 500 Hz, 20 V
// carrier on the estimated d axis; the q-axis current response, band-passed and demodulated
// (heterodyne), is proportional to (1/Lq - 1/Ld) sin(2 th_err); a PI phase-locked loop drives it
// to zero and yields speed and angle. The HF components are removed from the currents the
// current controllers see. The 180 deg ambiguity is harmless for a SynRM. Where the shaft makes an
// angle error grow (above the MTPA angle, shaft_stiffness.hpp) the PLL's bandwidth is raised.
#pragma once

#include "emulator/firmware/estimators/estimator.hpp"
#include "emulator/firmware/estimators/shaft_stiffness.hpp"
#include "emulator/firmware/estimators/tracking_observer.hpp"
#include "emulator/firmware/pi.hpp"

namespace synbench::emulator::firmware {

struct HfiParams {
  double ts_s = 1e-4;
  double voltage_V = 20.0;            // carrier amplitude (Sec. 6.2.2)
  double frequency_Hz = 500.0;        // carrier frequency (Sec. 6.2.2)
  // [assumed] thesis 25 Hz: that band-pass's 13 ms envelope lag sat inside the PLL.
  double bandpass_bandwidth_Hz = 200.0;
  double demod_lowpass_s = 2e-3;      // [assumed] removes the 2 f_hf product of the heterodyne
  double pll_bandwidth_Hz = 10.0;     // [assumed]
  // Incremental inductances that scale the demodulated error to radians [assumed: typical
  // operating values]; a wrong value only changes the PLL's loop gain.
  double ld_hf_H = 0.5;
  double lq_hf_H = 0.12;
  // Raises the PLL bandwidth where the shaft makes an angle error grow (inertia 0: off).
  ShaftStiffnessParams stiffness;
  double stiffness_current_filter_s = 0.02;  // [assumed] smoothing of the currents it takes
  // [assumed] Initial position detection: after a start the carrier runs this long with no
  // torque current, so the PLL finds the rotor before the speed loop turns the shaft with a
  // wrong angle (a start 58 deg off drove the shaft backwards into an over-current trip).
  double align_s = 0.1;
};

class Hfi final : public Estimator {
 public:
  explicit Hfi(const HfiParams& p = {});
  void update(const EstimatorInput& in) override;
  EstimatorOutput output() const override;
  void injection(double& ud_V, double& uq_V) const override;
  void fundamental(double& id_A, double& iq_A) const override;
  // Handed the angle by another source: nothing left to find.
  void align(double theta_e_rad, double omega_e_rad_s) override {
    pll_.reset(theta_e_rad, omega_e_rad_s);
    align_steps_ = 0;
  }
  bool aligning() const override { return step_ < align_steps_; }

 private:
  HfiParams p_;
  double w_hf_, delay_rad_, gain_A_per_rad_;
  long step_ = 0;
  long align_steps_;
  BandPass bp_d_, bp_q_;
  LowPass demod_;
  TrackingObserver pll_;
  StiffnessTuner tuner_;
};

}  // namespace synbench::emulator::firmware
