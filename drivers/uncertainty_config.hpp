// The type B inputs of a point's uncertainty budget (bench/uncertainty.hpp): the standard
// uncertainties (k = 1) of the bench's calibrations and sensors, one key each in a bench
// config's "uncertainty" section (drivers/bench_config.hpp). The thesis states none of them:
// every default is [assumed] (docs/uncertainty.md gives the reasoning for each), except the
// encoder's resolution (12 bit, physics.md Sec. 2).
#pragma once

namespace synbench::drivers {

struct UncertaintyConfig {
  // VFC meter (physics.md Sec. 4): I = (N / T_g - f0) / Kf.
  double vfc_f0_u_Hz = 20.0;          // zero-current frequency f0 after calibration
  double vfc_kf_u_pct = 0.1;          // its gain Kf, relative
  double meter_clock_u_ppm = 50.0;    // the MCU timer's clock, relative (the gate time T_g)
  // The DC-bus current sensor feeding the VFC (a shunt amplifier or a closed-loop hall sensor).
  double dc_sensor_gain_u_pct = 0.2;
  double dc_sensor_offset_u_A = 0.002;
  // A power meter's own DC powers (instead of the VFC): relative, of the reading.
  double power_meter_u_pct = 0.1;
  // The SynRM drive's U_dc measurement (its 12-bit ADC channel and divider).
  double udc_gain_u_pct = 0.5;
  double udc_offset_u_V = 0.5;
  // The load's torque, from its phase currents and torque constant kt.
  double torque_gain_u_pct = 1.0;
  double torque_offset_u_Nm = 0.005;
  // The load machine's viscous friction B1G (P_m = T_L w + B1G w^2).
  double load_b1_u_Nms_per_rad = 5.0e-5;
  // The SynRM drive's phase current sensors (I_m).
  double im_gain_u_pct = 1.0;
  // Encoder counts per revolution: the speed's quantisation over the window.
  double encoder_counts_per_rev = 4096.0;
};

}  // namespace synbench::drivers
