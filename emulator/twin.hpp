// The bench's twin: SynRM, PMSM load, shared DC bus, both inverters, VFC meter, MCIDC
// measurement, thermal node and both drives' firmware, advanced together in fixed PWM periods
// (100 us) on virtual time. The plant is integrated with Heun's method on flux linkage; the
// drives see only what their sensors see (noisy quantized currents, encoder counts, U_dc).
#pragma once

#include <cstdint>
#include <optional>

#include "drivers/devices.hpp"
#include "emulator/dc_bus.hpp"
#include "emulator/firmware/load_drive.hpp"
#include "emulator/firmware/synrm_drive.hpp"
#include "emulator/inverter_model.hpp"
#include "emulator/mcidc.hpp"
#include "emulator/noise.hpp"
#include "emulator/synrm_model.hpp"
#include "emulator/thermal.hpp"
#include "emulator/twin_config.hpp"
#include "emulator/vfc_meter.hpp"

namespace synbench::emulator {

// Continuous states of the plant.
struct PlantState {
  double psi_d_Wb = 0, psi_q_Wb = 0;
  double speed_rad_s = 0;  // mechanical
  double angle_rad = 0;    // mechanical, multi-turn
  double udc_V = 0;
  double load_iq_A = 0;    // load drive's braking current (closed-loop response)
};

// Instantaneous plant values, for tests and the truth record.
struct PlantSnapshot {
  double id_A = 0, iq_A = 0, id0_A = 0, iq0_A = 0;
  double torque_Nm = 0, load_torque_Nm = 0;
  double speed_rpm = 0, udc_V = 0, temp_C = 0;
  double ud_V = 0, uq_V = 0;  // terminal voltage in the true rotor frame
  bool brake_on = false;
};

// Faults a test injects into the plant (the twin's physical fault hooks; the Modbus link faults
// live with the register server).
struct PlantFaults {
  double source_offset_V = 0;          // mains surge on the rectified source
  double phase_a_sensor_offset_A = 0;  // current-sensor fault on phase a
};

class Twin {
 public:
  explicit Twin(const TwinConfig& config);

  void step();
  void run_steps(std::int64_t n) {
    for (std::int64_t i = 0; i < n; ++i) step();
  }
  double time_s() const { return static_cast<double>(steps_) * ts_; }
  std::uint64_t steps() const { return steps_; }
  double step_s() const { return ts_; }
  const TwinConfig& config() const { return cfg_; }

  firmware::SynrmDriveFirmware& synrm_drive() { return synrm_fw_; }
  firmware::LoadDriveFirmware& load_drive() { return load_fw_; }

  // Opens one window on the drives, the meter and the truth accumulator, starting at the next
  // period and lasting round(window_s / step) periods on all of them, rounded to a multiple of
  // firmware.window_batches (from that many periods on) so its batches are equal.
  void open_window(double window_s);
  bool window_open() const { return window_pending_ > 0 || window_left_ > 0; }
  const drivers::MeterReading& meter_reading() const { return vfc_.reading(); }
  const VfcMeter& vfc() const { return vfc_; }
  std::optional<drivers::TruthWindow> truth_window() const { return truth_; }

  PlantSnapshot snapshot() const;
  PlantFaults& faults() { return faults_; }
  // Sets the winding temperature (a cooling failure's result, or a test's starting point).
  void set_winding_temp_C(double t) { thermal_.set_temp_C(t); }
  const PlantState& state() const { return x_; }
  const SynrmModel& synrm_model() const { return synrm_; }
  // The last MCIDC sample (none when the active vector was too short or the gates are off).
  // Sampled only when the selected estimator needs it (it costs a Gaussian per period).
  const std::optional<McidcSample>& mcidc_sample() const { return mcidc_sample_; }

 private:
  struct Rates;
  Rates evaluate(const PlantState& x, double ua, double ub, bool gates, double rs,
                 double load_iref, double p_inv_m, double p_inv_g) const;
  // The same with the rotor angle's cos and sin and the machine's flows at x already known (the
  // step has them for its first slope: one sincos and one flux-map inversion fewer per period).
  Rates evaluate_at(const PlantState& x, double c, double s, SynrmFlows flows, double ua, double ub, bool gates,
                    double rs, double load_iref, double p_inv_m, double p_inv_g) const;
  double load_inverter_loss_W(const PlantState& x) const;

  TwinConfig cfg_;
  double ts_;
  SynrmModel synrm_;
  InverterModel inverter_;
  DcBus bus_;
  VfcMeter vfc_;
  Mcidc mcidc_;
  ThermalNode thermal_;
  firmware::SynrmDriveFirmware synrm_fw_;
  firmware::LoadDriveFirmware load_fw_;
  Noise noise_;
  double counts_per_rev_;
  double encoder_offset_rad_;  // mechanical: the plant's encoder mounting offset
  double total_inertia_kgm2_;  // the plant's, SynRM and load machine
  double load_kt_;

  PlantFaults faults_;
  PlantState x_;
  std::uint64_t steps_ = 0;
  firmware::DriveOutput applied_;  // the command in force during this period
  double load_iref_A_ = 0;
  std::optional<McidcSample> mcidc_sample_;

  std::int64_t window_pending_ = 0, window_left_ = 0, window_steps_ = 0;
  std::int64_t batch_steps_ = 0;  // periods per batch (0: the window keeps no batches)
  double t_pin_ = 0, t_pcu_ = 0, t_pfe_ = 0, t_pmech_ = 0, t_pinv_ = 0, t_pm_ = 0, t_temp_ = 0;
  std::optional<drivers::TruthWindow> truth_;
};

}  // namespace synbench::emulator
