// The twin's parameters: every physical constant of the emulated bench, in one struct tree.
// Defaults are the thesis values (physics.md); values the thesis does not give are marked
// [assumed] in the parameter table (twin_config_schema.cpp), which also validates and documents.
#pragma once

#include <array>
#include <string>
#include <string_view>

#include "drivers/modes.hpp"

namespace synbench::emulator {

// The config's choices, each with its names by value (the config file's spelling).
enum class LowSpeedSource { hfi, encoder };  // what EEMF hands over to below its minimum speed
inline constexpr std::array<std::string_view, 2> kLowSpeedSourceNames{"hfi", "encoder"};
enum class LutRotationSpeed { observer, active_flux };  // the rotor speed EEMF-LUT rotates its map with
inline constexpr std::array<std::string_view, 2> kLutRotationSpeedNames{"observer", "active-flux"};
enum class EemfErrorSignal { direction, vector };  // the EEMF angle error: direction alone, or the whole vector
inline constexpr std::array<std::string_view, 2> kEemfErrorSignalNames{"direction", "vector"};
// What a drive does with the master's disable: the gates off at once (a safe torque off, synbench's
// own firmware), or the speed ramped to zero first and then the gates off (an SS1-style stop, as
// many commercial drives do on their run bit; the state reads stopping meanwhile).
enum class DisableAction { gates_off, ramp };
inline constexpr std::array<std::string_view, 2> kDisableActionNames{"gates_off", "ramp"};

// Saturated flux linkage of one axis (thesis 1.22, Table 1.2).
struct FluxAxisParams {
  double l0_H = 0;      // unsaturated inductance
  double psi0_Wb = 0;   // saturated-branch offset
  double l1_H = 0;      // saturated-branch slope
  double beta_WbA = 0;  // saturated-branch hyperbolic term (negative)
};

struct SynrmParams {
  int pole_pairs = 2;
  double rs_ohm = 9.68;
  double rs_ref_temp_C = 50.0;
  double rs_temp_coeff_per_K = 0.00393;
  double inertia_kgm2 = 1.64e-3;
  double b1_Nms_per_rad = 1.96e-3;
  double b2_Nms2_per_rad2 = 1.0e-6;
  FluxAxisParams flux_d{0.670, 1.30, 0.026, -0.647};
  FluxAxisParams flux_q{0.382, 0.11, 0.081, -0.0085};
  double core_kh_Ws_per_radWb2 = 0.03925;
  double core_ke_Ws2_per_rad2Wb2 = 1.25e-4;
};

struct ThermalParams {
  double capacity_J_per_K = 4000.0;
  double resistance_K_per_W = 0.6;
  double ambient_C = 25.0;
  double initial_C = 50.0;
};

struct LoadParams {
  int pole_pairs = 4;
  double psi_pm_Wb = 0.15;
  double rs_ohm = 1.2;
  double ls_H = 5.0e-3;
  double inertia_kgm2 = 2.0e-3;
  double b1_Nms_per_rad = 2.0e-4;
  double current_bandwidth_Hz = 200.0;
  double current_limit_A = 10.0;
  double torque_ramp_Nm_per_s = 10.0;
};

struct EncoderParams {
  int resolution_bits = 12;
};

// The machine as built against the model the drive firmware and its estimators hold (synrm):
// factors on the plant's flux maps, resistance and inertia, and the encoder's mounting offset.
// The firmware keeps the nominal synrm values, so a study can ask how an estimator's error grows
// when the machine differs from its model (thesis Ch. 4; docs/study.md). 1 and 0: the model.
struct PlantParams {
  double flux_d_scale = 1.0;     // the plant's Psi_d(i_d) = scale x the model's (Ld, every branch)
  double flux_q_scale = 1.0;     // the same for Psi_q(i_q)
  double rs_scale = 1.0;         // the plant's R_s = scale x synrm.rs_ohm (at every temperature)
  double inertia_scale = 1.0;    // the SynRM rotor's J = scale x synrm.inertia_kgm2
  double encoder_offset_deg = 0;  // electrical: the encoder reads the rotor this far ahead
};

struct InverterParams {
  double pwm_frequency_Hz = 10000.0;
  double dead_time_s = 1.0e-6;
  bool dead_time_compensation = true;
  double dead_time_current_band_A = 0.05;
  double vce0_V = 0.85;
  double rce_ohm = 0.05;
  double vf0_V = 0.95;
  double rf_ohm = 0.07;
  double esw0_J = 20.0e-6;
  double esw_per_A_J = 40.0e-6;
  double esw_ref_V = 400.0;
};

struct DcBusParams {
  double source_V = 425.0;
  double source_ohm = 2.0;
  double capacitance_F = 1.0e-3;
  double brake_on_V = 440.0;
  double brake_off_V = 430.0;
  double brake_ohm = 100.0;
};

struct VfcChannelErrors {
  double gain_error = 0.0;      // relative error of the converter's true gain
  double offset_error_A = 0.0;  // input-referred offset of the converter
};

struct VfcParams {
  double f0_Hz = 500.0e3;
  double kf_Hz_per_A = 100.0e3;
  VfcChannelErrors motor;
  VfcChannelErrors generator;
};

struct McidcParams {
  double noise_sigma_per_H = 0.15;
  double gain_error = 0.0;
  double deformation_amplitude_per_H = 0.05;
  int deformation_harmonic = 4;
  double min_active_time_s = 10.0e-6;
};

struct FirmwareParams {
  double current_bandwidth_Hz = 40.0;
  double speed_bandwidth_Hz = 3.0;
  double speed_loop_rate_Hz = 1000.0;
  double speed_observer_bandwidth_Hz = 50.0;
  double current_noise_sigma_A = 0.0158;
  int adc_bits = 12;
  double adc_range_A = 8.0;
  double current_limit_A = 4.0;
  double speed_ramp_rpm_per_s = 1000.0;
  double sensorless_angle_slew_deg_per_s = 30.0;
  // Lock guard (LockGuard): a sensorless angle off the encoder's by more than this, for this
  // long, hands the FOC to the encoder until the next operating point (0 deg: off).
  double lock_guard_deg = 45.0;
  double lock_guard_speed_rpm = 150.0;  // or a speed estimate this far off the encoder's (0: off)
  double lock_guard_s = 0.05;
  double lock_guard_current_A = 5.0;  // or a current vector this large (0: off)
  double telemetry_filter_s = 0.05;
  // Equal consecutive sub-windows (batches) a measurement window's means are also kept over, on
  // both drives and the VFC meter: the bench's type A uncertainty comes from their scatter.
  int window_batches = 10;
  double max_speed_rpm = 1500.0;
  double overspeed_trip_rpm = 1800.0;
  double overcurrent_trip_A = 6.0;
  double overvoltage_trip_V = 450.0;
  double undervoltage_trip_V = 300.0;
  double overtemp_trip_C = 120.0;
  drivers::Pwm pwm = drivers::Pwm::capwm;
  DisableAction disable_action = DisableAction::gates_off;
  // The drive's documented stop time (its manual's): how long a disable may take to read back
  // not running. 0 for gates_off; ramp: max_speed_rpm / speed_ramp_rpm_per_s.
  double stop_time_s() const {
    return disable_action == DisableAction::ramp ? max_speed_rpm / speed_ramp_rpm_per_s : 0.0;
  }
};

// Sensorless estimators (physics.md 8). The EKFs keep the thesis tuning of their own params.
struct HfiConfig {
  double voltage_V = 20.0;
  double frequency_Hz = 500.0;
  double bandpass_bandwidth_Hz = 200.0;  // thesis 25 Hz; docs/estimators.md
  double pll_bandwidth_Hz = 10.0;
  double align_s = 0.1;  // initial position detection: carrier without torque current
};

struct EemfConfig {
  double ld_H = 0.65;
  double lq_H = 0.2;
  double observer_bandwidth_Hz = 5.0;
  double stiffness_margin = 1.5;   // observer wn >= margin x the shaft's error growth rate (as HFI)
  double speed_filter_s = 0.002;   // low-pass on the speed the observer reports
  double min_speed_rpm = 500.0;
  double handover_hysteresis_rpm = 25.0;
  LowSpeedSource low_speed_source = LowSpeedSource::encoder;
  double lut_ld_scale = 1.0;
  double lut_lq_scale = 1.0;
  double rls_forgetting = 0.99;
  double rls_p0 = 1e5;
  double rls_sample_s = 1e-3;
  double rls_estimate_filter_s = 0.2;  // low-pass on the estimates reported
  double rls_model_filter_s = 2.0;     // low-pass on the estimates the observer uses
  double rls_warmup_s = 0.3;           // identification time before the observer uses it
  LutRotationSpeed lut_rotation_speed = LutRotationSpeed::observer;  // the thesis; or active-flux [ours]
  // EEMF-LUT and EEMF-RLS: the angle error from the EEMF's "direction" (the thesis) or its whole
  // "vector" against the model's magnitude [ours]; EEMF-CONST always the direction.
  EemfErrorSignal error_signal = EemfErrorSignal::vector;
  double rls_emf_scale_filter_s = 0.2;  // EEMF-RLS: the predicted magnitude scaled to the measured
  bool rls_flux_offset = true;  // EEMF-RLS: static flux from the identified flux offsets [ours]
  double flux_blend_rad_s = 5.0;
  double flux_speed_filter_s = 0.015;
  double prbs_voltage_V = 20.0;
  double prbs_bit_s = 0.01;
};

struct EkfConfig {
  double rs_speed_threshold_rpm = 100.0;
};

struct EstimatorsParams {
  HfiConfig hfi;
  EemfConfig eemf;
  EkfConfig ekf;
};

struct SimParams {
  int seed_int = 1;  // noise generator seed
};

struct TwinConfig {
  SynrmParams synrm;
  ThermalParams thermal;
  LoadParams load;
  EncoderParams encoder;
  PlantParams plant;
  InverterParams inverter;
  DcBusParams dc_bus;
  VfcParams vfc;
  McidcParams mcidc;
  FirmwareParams firmware;
  EstimatorsParams estimators;
  SimParams sim;

  double total_inertia_kgm2() const { return synrm.inertia_kgm2 + load.inertia_kgm2; }
  // The plant's machine: synrm with plant's factors applied (what the twin simulates).
  SynrmParams plant_synrm() const;
  double step_s() const { return 1.0 / inverter.pwm_frequency_Hz; }

  // Operates the same bus design at another voltage: source voltage set to udc_V, chopper and
  // over/under-voltage trips scaled in the same ratio (so a 560 V what-if bus does not trip).
  void scale_bus_to(double udc_V);
};

}  // namespace synbench::emulator
