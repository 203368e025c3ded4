// Extended-EMF observer (physics.md 8, thesis 2.12, 2.13, Sec. 6.2.3): in the estimated frame
// e_g = u_g - (Rs + L'd p) i_g + w Lq i_d, e_d = u_d - (Rs + L'd p) i_d - w Lq i_g; the angle
// error atan2(-e_g, e_d) (or, [ours], the whole EEMF vector against the model's prediction:
// emf_angle_error.hpp) drives a PI tracking observer (5 Hz, raised where the shaft makes an
// angle error grow) whose integral is the angle; p i is taken in a frame turning at the estimated
// rotor speed, and the reported speed (the PI's output) is low-passed. The rotor speed in those
// rotation terms is the observer's integrator (the thesis) or the active flux's
// (active_flux_speed.hpp) [ours].
// Three sources of Rs, L'd, Lq as in the thesis: constant (Ld = 0.65 H, Lq = 0.2 H), the
// flux-map tables (optionally deformed, thesis 4.1 and 4.2), or RLS identification excited by
// PRBS voltage injection on both axes (for the observer over a slow model, completed by the RLS's
// flux offsets into the static flux [ours]; docs/estimators.md).
#pragma once

#include <optional>

#include "emulator/firmware/estimators/active_flux_speed.hpp"
#include "emulator/firmware/estimators/emf_angle_error.hpp"
#include "emulator/firmware/estimators/estimator.hpp"
#include "emulator/firmware/estimators/rls.hpp"
#include "emulator/firmware/estimators/shaft_stiffness.hpp"
#include "emulator/firmware/estimators/tracking_observer.hpp"
#include "emulator/firmware/pi.hpp"
#include "emulator/flux_map.hpp"
#include "emulator/twin_config.hpp"

namespace synbench::emulator::firmware {

enum class EemfModel { constant, lut, rls };

// Where the rotor speed of the EEMF's rotation terms (w Lq, the derivative's frame) comes from.
enum class EemfRotationSpeed { observer, active_flux };

struct EemfParams {
  double ts_s = 1e-4;
  EemfModel model = EemfModel::constant;
  double rs_ohm = 9.68;                 // constant Rs of the const and LUT variants
  double ld_H = 0.65, lq_H = 0.2;       // constant variant (Sec. 6.2.3)
  FluxAxisParams flux_d{0.670, 1.30, 0.026, -0.647};  // LUT variant: the drive's flux maps
  FluxAxisParams flux_q{0.382, 0.11, 0.081, -0.0085};
  double lut_ld_scale = 1.0;            // kd of the table deformation L = k f(i / k) (4.1)
  double lut_lq_scale = 1.0;            // kq (4.2)
  double observer_bandwidth_Hz = 5.0;   // Sec. 6.2.3
  // Raises the observer's bandwidth where the shaft makes an angle error grow (above the MTPA
  // angle; shaft_stiffness.hpp), from the currents smoothed over `stiffness_current_filter_s`.
  ShaftStiffnessParams stiffness;
  double stiffness_current_filter_s = 0.02;  // [assumed]
  double speed_filter_s = 0.0;          // [assumed] low-pass on the reported speed (0: none)
  double emf_filter_s = 5e-3;           // [assumed] low-pass on e before the angle error
  double emf_floor_V = 5.0;             // [assumed] |e| below which the angle error is faded out
  // [ours] The angle error from the whole EEMF vector, its magnitude against the model's
  // prediction as well (emf_angle_error.hpp); false: from its direction only (the thesis).
  bool vector_error = false;
  double emf_scale_filter_s = 0.0;      // [assumed] EmfScale time constant (0: the model as is)
  EemfRotationSpeed rotation_speed = EemfRotationSpeed::observer;
  ActiveFluxSpeedParams flux_speed;     // for EemfRotationSpeed::active_flux
  double rls_forgetting = 0.99;         // Sec. 6.2.3
  double rls_p0 = 1e5;
  double rls_sample_s = 1e-3;           // [assumed] RLS sample period (a multiple of ts_s)
  double rls_estimate_filter_s = 0.2;   // [assumed] low-pass on the estimates reported
  // [assumed] Low-pass on the estimates the observer uses: much slower than the identification
  // (docs/estimators.md): identified in the estimated frame, they move with the observer's own
  // angle error, and followed closely that loop lost the rotor at high current angles.
  double rls_model_filter_s = 2.0;
  // [assumed] The observer runs on the constants until the RLS has identified this long: from
  // P0 = 1e5 I its first estimates are whatever the first few intervals fit.
  double rls_warmup_s = 0.3;
  // [ours] The RLS's flux offsets (its affine part, rls.hpp) complete its linear model into the
  // static flux the rotation terms and the magnitude prediction need: Lq = L'q + psi_off_q / i_q,
  // Psi_d = L'd i_d + psi_off_d. false: the incremental inductances as they are (the thesis).
  bool rls_flux_offset = true;
  double prbs_voltage_V = 20.0;         // Sec. 6.2.3
  double prbs_bit_s = 0.01;
};

class Eemf final : public Estimator {
 public:
  explicit Eemf(const EemfParams& p);
  void update(const EstimatorInput& in) override;
  EstimatorOutput output() const override;
  void injection(double& ud_V, double& uq_V) const override;
  void align(double theta_e_rad, double omega_e_rad_s) override {
    obs_.reset(theta_e_rad, omega_e_rad_s);
    speed_f_.reset(omega_e_rad_s);
    flux_speed_.align(omega_e_rad_s);
  }

 private:
  void inductances(double ig, double id, double& ld_dyn, double& lq_static) const;
  // A deformed table's static inductance L^ = k f(i / k) (thesis 4.1, 4.2).
  static double lut_static_H(const FluxAxis& axis, double k, double i) {
    return k * axis.static_inductance_H(i / k);
  }
  // The model's flux linkages and static q inductance at the present currents (not smoothed:
  // the active flux psi - Lq i must lose its q part at every instant, transients included).
  struct Flux {
    double psi_g_Wb, psi_d_Wb, lq_static_H;
  };
  Flux model_flux(double ig, double id) const;
  // The model's EEMF at zero angle error and its slope, from its flux at the smoothed currents,
  // before the EMF filter (which the caller applies as to e).
  EmfPrediction predict(double ig_s, double id_s, double ld_dyn, double w_rot, double did) const;
  void update_flux_speed(const EstimatorInput& in, double th, double ig, double id, double rs);

  EemfParams p_;
  FluxAxis fd_, fq_;
  TrackingObserver obs_;
  LowPass eg_f_, ed_f_, ig_f_, id_f_, e0_f_, k_f_;
  EmfScale scale_;
  StiffnessTuner tuner_;
  LowPass speed_f_;
  ActiveFluxSpeed flux_speed_;
  double ia_prev_ = 0, ib_prev_ = 0;  // the last current sample, stationary frame
  bool have_prev_ = false;
  // RLS and its excitation.
  std::optional<StatorRls> rls_;
  // What the RLS identified, smoothed for the record (estimate_) and, slower, for the observer:
  // the inductances, Rs and the flux offsets psi = L' i + psi_off (model_), on the estimated
  // frame's gamma (d) and delta (q) axes as everywhere here.
  struct RlsModel {
    double rs_ohm, ld_H, lq_H, psi_off_g_Wb = 0, psi_off_d_Wb = 0;
  };
  void take_rls_fit(const StatorEstimate& e, double w);
  std::optional<StatorEstimate> estimate_;
  std::optional<RlsModel> model_;
  Prbs5 prbs_g_{0b10011}, prbs_d_{0b01101};
  double inj_g_ = 0, inj_d_ = 0;
  int rls_every_ = 10, rls_count_ = 0;
  long rls_intervals_ = 0, rls_warmup_intervals_ = 0;
  bool rls_have_prev_ = false;
  double rls_ig0_ = 0, rls_id0_ = 0;
  double rls_ug_sum_ = 0, rls_ud_sum_ = 0, rls_ig_sum_ = 0, rls_id_sum_ = 0;
};

}  // namespace synbench::emulator::firmware
