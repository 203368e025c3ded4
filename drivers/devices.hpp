// Typed device interfaces of the bench: the SynRM drive, the PMSM load drive, the VFC power
// meter, and the trigger that opens one measurement window on all of them at once. Real
// inverters (through device profiles and Modbus) and the twin implement the same interfaces, as
// ros2_control's mock and real hardware share one.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "drivers/fault.hpp"
#include "drivers/modes.hpp"

namespace synbench::drivers {

enum class DriveState : std::uint16_t { disabled = 0, running = 1, stopping = 2, faulted = 3 };

// The state as the API, the command line and the database name it.
constexpr const char* state_name(DriveState s) {
  switch (s) {
    case DriveState::disabled: return "disabled";
    case DriveState::running: return "running";
    case DriveState::stopping: return "stopping";
    case DriveState::faulted: return "faulted";
  }
  return "?";
}

// Gates on: running, or in the drive's own ordered stop.
inline bool running(DriveState s) { return s == DriveState::running || s == DriveState::stopping; }

// Filtered live values of the SynRM drive (controller frame for d, q).
struct SynrmTelemetry {
  double speed_rpm = 0;
  double im_A = 0;
  double id_A = 0;
  double iq_A = 0;
  double ud_V = 0;
  double uq_V = 0;
  double udc_V = 0;
  double pac_W = 0;  // 1.5 (ud id + uq iq): the drive's own estimate of its output power
  std::optional<double> temp_C;  // empty when the drive's profile maps no temp_C
  bool voltage_limited = false;
  // Estimated minus encoder electrical angle, wrapped to (-90, 90] deg, at the last control
  // period; empty when the encoder is the position source, and while the lock guard holds.
  std::optional<double> pos_err_deg;
  // The drive's lock guard took the angle from a sensorless estimator that left the encoder's
  // (a slipped observer) and runs on the encoder until a changed speed or angle setpoint is
  // reached.
  bool lock_lost = false;
  DriveState state = DriveState::disabled;
  Fault fault = Fault::none;
  std::optional<std::int64_t> fault_code_raw;  // the device's code of an unknown fault
};

// Who kept a measurement window: the device (its window registers; samples are its control
// periods) or the bench (telemetry polled every poll_period_ms; samples are the polls).
enum class WindowKeeper { device, host };

constexpr const char* keeper_name(WindowKeeper k) { return k == WindowKeeper::host ? "host" : "device"; }

// How the bench sampled a window it kept (keeper host): the poll period asked for and the
// longest time between two samples taken, so the point can refuse a window the bench stopped
// polling in (bench/window_plausibility.hpp).
struct HostSampling {
  double poll_period_s = 0;
  double longest_gap_s = 0;
};

// Results of one measurement window, accumulated by the drive at its control rate (or by the
// bench from polled telemetry: keeper host).
struct SynrmWindow {
  std::uint32_t samples = 0;
  double window_s = 0;
  double speed_meas_rpm = 0;  // from encoder counts over the window
  double im_A = 0, id_A = 0, iq_A = 0, ud_V = 0, uq_V = 0, udc_V = 0;
  std::optional<double> temp_C;  // empty when the drive reports no temperature
  double voltage_limited_fraction = 0;
  // Fraction of the samples in which a low-speed fallback gave the angle instead of the selected
  // estimator (an EEMF observer below its minimum speed hands over to HFI or the encoder).
  double fallback_fraction = 0;
  // Fraction of the samples the lock guard ran on the encoder (see SynrmTelemetry::lock_lost).
  double lock_lost_fraction = 0;
  // Estimator outputs; empty when the position source is the encoder.
  std::optional<double> pos_err_min_deg, pos_err_mean_deg, pos_err_max_deg, speed_err_rpm;
  std::optional<double> ld_est_H, lq_est_H, rs_est_ohm;
  // References at the operating point the estimates are judged against (dynamic inductances
  // from the drive's flux maps, Rs at the winding temperature); empty for the encoder.
  std::optional<double> ld_ref_H, lq_ref_H, rs_ref_ohm;
  Fault fault = Fault::none;  // fault latched during the window, if any
  WindowKeeper keeper = WindowKeeper::device;
  std::optional<std::int64_t> fault_code_raw;  // the device's code of an unknown fault
  HostSampling host;  // keeper host only
  // The window's means over its equal consecutive sub-windows (batches), in time order: the
  // type A uncertainty of the window's mean comes from their scatter (bench/uncertainty.hpp).
  // Empty when the device keeps no batches.
  std::vector<double> batch_im_A, batch_speed_meas_rpm;
};

// The step of each telemetry value the frozen-telemetry check watches, as the drive's registers
// carry it: an integer register's value moves only in whole steps of its scale, so a steady
// value of a coarse register reads bit for bit the same without anything being stuck; 0 for a
// float register or an in-process value (continuous). drivers/frozen_watch.hpp says which steps
// are too coarse to watch.
struct TelemetryResolution {
  double speed_rpm = 0, im_A = 0, id_A = 0, iq_A = 0, ud_V = 0, uq_V = 0;
};

class SynrmDrive {
 public:
  virtual ~SynrmDrive() = default;
  virtual std::error_code enable(bool on) = 0;
  // One disable request, not repeated inside the call when it is lost: a stop of both drives
  // has each tried once before either is tried again (the safety supervisor repeats it).
  virtual std::error_code disable_once() { return enable(false); }
  virtual std::error_code set_speed_rpm(double speed_rpm) = 0;
  virtual std::error_code set_angle_deg(double angle_deg) = 0;
  virtual std::error_code set_pwm(Pwm pwm) = 0;
  virtual std::error_code set_estimator(Estimator estimator) = 0;
  virtual std::error_code reset_fault() = 0;
  virtual std::error_code read(SynrmTelemetry& out) = 0;
  // The result of the last closed window; errc::not_ready while it is open.
  virtual std::error_code read_window(SynrmWindow& out) = 0;
  // What the last failed call ran into in the device's terms (signal, register, raw words),
  // for the message that reports it; empty when there is nothing to add.
  virtual std::string error_detail() const { return {}; }
  // The steps of the telemetry read() returns; the default: continuous (a twin, a float map).
  virtual TelemetryResolution resolution() const { return {}; }
  // The drive's documented stop time: how long after an acknowledged disable it may still read
  // running or stopping (an SS1-style drive ramps down on its run bit); 0: at once (gates off).
  // The safety supervisor alarms only past it (bench/safety_supervisor.hpp).
  virtual double stop_time_s() const { return 0.0; }
};

struct LoadTelemetry {
  double torque_Nm = 0;  // braking torque magnitude from the measured current
  double iq_A = 0;
  DriveState state = DriveState::disabled;
  Fault fault = Fault::none;
  std::optional<std::int64_t> fault_code_raw;  // the device's code of an unknown fault
};

struct LoadWindow {
  std::uint32_t samples = 0;
  double torque_Nm = 0;
  WindowKeeper keeper = WindowKeeper::device;
  double window_s = 0;  // keeper host: from the first sample to the last; else 0 (not reported)
  HostSampling host;    // keeper host only
  std::vector<double> batch_torque_Nm;  // as SynrmWindow's batches
};

class LoadDrive {
 public:
  virtual ~LoadDrive() = default;
  virtual std::error_code enable(bool on) = 0;
  virtual std::error_code disable_once() { return enable(false); }  // as SynrmDrive's
  // Braking torque magnitude; the drive applies it against the direction of rotation.
  virtual std::error_code set_torque_Nm(double torque_Nm) = 0;
  virtual std::error_code reset_fault() = 0;
  virtual std::error_code read(LoadTelemetry& out) = 0;
  virtual std::error_code read_window(LoadWindow& out) = 0;
  virtual std::string error_detail() const { return {}; }  // as SynrmDrive's
  virtual double stop_time_s() const { return 0.0; }         // as SynrmDrive's
};

// VFC counts of the two DC-bus currents over the gate, and the currents the meter derives; or
// (a power meter) the instrument's average DC powers over the window, sampled by the bench.
struct MeterReading {
  std::uint64_t counts_m = 0;
  std::uint64_t counts_g = 0;
  double gate_s = 0;
  double idcm_A = 0;
  double idcg_A = 0;
  // Set by a power meter: the bench then takes these instead of udc_V x idc (idcm_A and idcg_A
  // stay 0: the meter does not measure them).
  std::optional<double> pdcm_W, pdcg_W;
  WindowKeeper keeper = WindowKeeper::device;
  std::uint32_t samples = 0;  // host-kept: the polls averaged
  HostSampling host;          // keeper host only
  // Pulses counted in each of the gate's equal consecutive sub-gates, in time order (they sum to
  // counts_m, counts_g): the type A uncertainty of the gate's currents. Empty without batches.
  std::vector<std::uint64_t> batch_counts_m, batch_counts_g;
  // The nominal calibration idcm_A and idcg_A were computed with (I = (N / T_g - f0) / Kf): what
  // turns batch counts into currents and a count into its current. 0 when not a VFC gate.
  double f0_Hz = 0, kf_Hz_per_A = 0;
};

class PowerMeter {
 public:
  virtual ~PowerMeter() = default;
  virtual std::error_code read(MeterReading& out) = 0;
  virtual std::string error_detail() const { return {}; }  // as SynrmDrive's
};

// Opens one window on every device at once (hardware: a broadcast or a trigger line).
class WindowTrigger {
 public:
  virtual ~WindowTrigger() = default;
  virtual std::error_code open_window(double window_s) = 0;
  virtual bool window_closed() = 0;
};

// The plant's own values over the last window; only a twin can offer them.
struct TruthWindow {
  double pin_W = 0, pcu_W = 0, pfe_W = 0, pmech_W = 0, pinvm_W = 0, pm_W = 0, temp_C = 0;
};

class TruthProbe {
 public:
  virtual ~TruthProbe() = default;
  virtual std::optional<TruthWindow> read_truth_window() = 0;
};

// What the bench needs from the hardware layer, whatever implements it.
struct BenchDevices {
  SynrmDrive* synrm = nullptr;
  LoadDrive* load = nullptr;
  PowerMeter* meter = nullptr;
  WindowTrigger* trigger = nullptr;
  TruthProbe* truth = nullptr;  // null on real hardware
};

}  // namespace synbench::drivers
