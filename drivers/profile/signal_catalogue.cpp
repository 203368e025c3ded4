// The signal catalogue. Required are the signals without which the bench cannot command a
// device or keep it safe; everything else is optional, and a driver answers errc::not_supported
// for an optional signal its profile leaves out. The window and meter signals are required as
// groups, by the profile's choice of window and meter (drivers/profile/window_schema.cpp).
#include "drivers/profile/signal_catalogue.hpp"

#include "drivers/fault.hpp"
#include "drivers/modes.hpp"

namespace synbench::drivers {
namespace {

using R = SignalRole;

// Labels come from the enums in drivers/ wherever those exist, so they cannot drift apart.
constexpr std::array<std::string_view, 4> kStateLabels{"disabled", "running", "stopping", "faulted"};
constexpr std::array<std::string_view, 3> kWindowStatusLabels{"idle", "open", "done"};
constexpr std::array<std::string_view, 10> kFaultLabels{
    fault_name(Fault::none),         fault_name(Fault::overcurrent), fault_name(Fault::overvoltage),
    fault_name(Fault::undervoltage), fault_name(Fault::overspeed),   fault_name(Fault::overtemperature),
    fault_name(Fault::watchdog),     fault_name(Fault::estop),       fault_name(Fault::link_loss),
    fault_name(Fault::load_drive)};

constexpr SignalSpec kSynrm[] = {
    {"enable", R::command, true, "", "1 runs the drive, 0 ramps it down and disables it"},
    {"speed_setpoint_rpm", R::command, true, "rpm", "speed reference"},
    {"angle_setpoint_deg", R::command, true, "deg", "current-vector angle from the d axis"},
    {"pwm_scheme", R::command, false, "", "switching scheme", kPwmNames},
    {"estimator", R::command, false, "",
     "position source", kEstimatorNames},
    {"fault_reset", R::fault_reset, true, "", "writing 1 clears a latched fault (held pulse_ms with \"reset\": pulse)"},
    {"heartbeat", R::heartbeat, false, "",
     "the bench writes a new value every period_ms; the drive trips (fault 6 watchdog) when it "
     "has not changed for timeout_ms (without it the profile names its \"watchdog\")"},
    {"window_start", R::window_start, false, "", "writing 1 opens a window of window_length_ms"},
    {"window_length_ms", R::window_length, false, "ms", "length of the next window"},
    {"state", R::telemetry, true, "", "drive state", kStateLabels},
    {"fault_code", R::telemetry, true, "", "latched fault (drivers/fault.hpp)", kFaultLabels},
    {"speed_rpm", R::telemetry, true, "rpm", "filtered speed"},
    {"im_A", R::telemetry, false, "A", "current-vector magnitude"},
    {"id_A", R::telemetry, false, "A", "d current"},
    {"iq_A", R::telemetry, false, "A", "q current"},
    {"ud_V", R::telemetry, false, "V", "d voltage"},
    {"uq_V", R::telemetry, false, "V", "q voltage"},
    {"udc_V", R::telemetry, false, "V", "DC-link voltage"},
    {"pac_W", R::telemetry, false, "W", "the drive's estimate of its output power"},
    {"temp_C", R::telemetry, false, "C", "power-stage temperature"},
    {"voltage_limited", R::telemetry, false, "", "1 while the voltage limit is active"},
    {"pos_err_deg", R::telemetry, false, "deg", "estimated minus encoder angle, last control period; not with the encoder"},
    {"lock_lost", R::telemetry, false, "", "1 while the lock guard runs a sensorless drive on the encoder (until a changed speed or angle setpoint is reached)"},
    {"window_status", R::window_status, false, "", "window state", kWindowStatusLabels},
    {"window_sequence", R::window_sequence, false, "", "increments (mod 65536) per closed window"},
    {"window_samples", R::window_result, false, "", "control periods accumulated"},
    {"window_s", R::window_result, false, "s", "accumulated duration"},
    {"window_fault_code", R::window_result, false, "", "fault latched during the window", kFaultLabels},
    {"window_speed_meas_rpm", R::window_result, false, "rpm", "speed from encoder counts over the window"},
    {"window_im_A", R::window_result, false, "A", "mean"},
    {"window_id_A", R::window_result, false, "A", "mean"},
    {"window_iq_A", R::window_result, false, "A", "mean"},
    {"window_ud_V", R::window_result, false, "V", "mean"},
    {"window_uq_V", R::window_result, false, "V", "mean"},
    {"window_udc_V", R::window_result, false, "V", "mean"},
    {"window_temp_C", R::window_result, false, "C", "mean"},
    {"window_voltage_limited_fraction", R::window_result, false, "", "fraction of samples voltage-limited, 0..1"},
    {"window_pos_err_min_deg", R::window_result, false, "deg", "estimator position error, minimum; not with the encoder"},
    {"window_pos_err_mean_deg", R::window_result, false, "deg", "estimator position error, mean; not with the encoder"},
    {"window_pos_err_max_deg", R::window_result, false, "deg", "estimator position error, maximum; not with the encoder"},
    {"window_speed_err_rpm", R::window_result, false, "rpm", "estimator speed error, mean; not with the encoder"},
    {"window_ld_est_H", R::window_result, false, "H", "estimated d inductance, mean; not with the encoder"},
    {"window_lq_est_H", R::window_result, false, "H", "estimated q inductance, mean; not with the encoder"},
    {"window_rs_est_ohm", R::window_result, false, "ohm", "estimated stator resistance, mean; not with the encoder"},
    {"window_fallback_fraction", R::window_result, false, "", "fraction of samples on the low-speed fallback source, 0..1"},
    {"window_lock_lost_fraction", R::window_result, false, "", "fraction of samples the lock guard ran on the encoder, 0..1"},
    {"window_estimates_present", R::window_result, false, "",
     "which estimator fields this window has, bits: 1 position and speed errors, 2 Ld, 4 Lq, 8 Rs; an absent field reads 0 (without this signal all are taken as present)"},
    {"window_batch_im_A", R::window_result, false, "A",
     "array (count): means of the window's equal consecutive sub-windows (batches), in time order", {}, true},
    {"window_batch_speed_meas_rpm", R::window_result, false, "rpm",
     "array (count): speed from encoder counts over each batch, in time order", {}, true},
};

constexpr SignalSpec kLoad[] = {
    {"enable", R::command, true, "", "1 runs the drive, 0 disables it"},
    {"torque_setpoint_Nm", R::command, true, "Nm", "braking torque magnitude, applied against the rotation"},
    {"fault_reset", R::fault_reset, true, "", "writing 1 clears a latched fault (held pulse_ms with \"reset\": pulse)"},
    {"heartbeat", R::heartbeat, false, "",
     "the bench writes a new value every period_ms; the drive trips (fault 6 watchdog) when it "
     "has not changed for timeout_ms (without it the profile names its \"watchdog\")"},
    {"window_start", R::window_start, false, "",
     "writing 1 opens a window of window_length_ms; for a bench without a trigger line"},
    {"window_length_ms", R::window_length, false, "ms", "length of the next window"},
    {"state", R::telemetry, true, "", "drive state", kStateLabels},
    {"fault_code", R::telemetry, true, "", "latched fault (drivers/fault.hpp)", kFaultLabels},
    {"torque_Nm", R::telemetry, true, "Nm", "braking torque magnitude from the measured current"},
    {"iq_A", R::telemetry, false, "A", "q current"},
    {"window_status", R::window_status, false, "", "window state", kWindowStatusLabels},
    {"window_sequence", R::window_sequence, false, "", "increments (mod 65536) per closed window"},
    {"window_samples", R::window_result, false, "", "control periods accumulated"},
    {"window_torque_Nm", R::window_result, false, "Nm", "mean braking torque"},
    {"window_batch_torque_Nm", R::window_result, false, "Nm",
     "array (count): mean braking torque over each of the window's equal consecutive sub-windows (batches), in time order",
     {}, true},
};

constexpr SignalSpec kMeter[] = {
    {"gate_start", R::window_start, false, "", "writing 1 opens a gate of gate_length_ms"},
    {"gate_length_ms", R::window_length, false, "ms", "length of the next gate"},
    {"gate_status", R::window_status, false, "", "gate state", kWindowStatusLabels},
    {"gate_sequence", R::window_sequence, false, "", "increments (mod 65536) per closed gate"},
    {"counts_m", R::window_result, false, "", "VFC pulses of the motor-side DC current over the gate"},
    {"counts_g", R::window_result, false, "", "VFC pulses of the generator-side DC current over the gate"},
    {"gate_s", R::window_result, false, "s", "measured gate duration"},
    {"idcm_A", R::window_result, false, "A", "motor-side DC current, (counts_m / gate_s - f0_Hz) / kf_Hz_per_A"},
    {"idcg_A", R::window_result, false, "A", "generator-side DC current, (counts_g / gate_s - f0_Hz) / kf_Hz_per_A"},
    {"batch_counts_m", R::window_result, false, "",
     "array (count): motor-side VFC pulses in each of the gate's equal consecutive sub-gates, in time order (they sum to counts_m)",
     {}, true},
    {"batch_counts_g", R::window_result, false, "",
     "array (count): generator-side VFC pulses in each of the gate's equal consecutive sub-gates, in time order (they sum to counts_g)",
     {}, true},
    {"f0_Hz", R::calibration, false, "Hz", "nominal converter frequency at zero current"},
    {"kf_Hz_per_A", R::calibration, false, "Hz/A", "nominal converter gain"},
    {"total_m", R::telemetry, false, "",
     "free-running count of the motor-side VFC pulses (meter totalizer; u16 or u32, wraps at its range)"},
    {"total_g", R::telemetry, false, "",
     "free-running count of the generator-side VFC pulses (meter totalizer; u16 or u32, wraps at its range)"},
    {"time_base_ticks", R::telemetry, false, "",
     "free-running count of the meter's clock of time_base_Hz (meter totalizer; u16 or u32, wraps at its range)"},
    {"pdcm_W", R::telemetry, false, "W", "motor-side DC power, the instrument's average (meter power)"},
    {"pdcg_W", R::telemetry, false, "W", "generator-side DC power, the instrument's average (meter power)"},
};

constexpr std::array<std::string_view, 3> kKindNames{"synrm_drive", "load_drive", "vfc_meter"};
constexpr std::array<std::string_view, 10> kRoleNames{
    "command",       "heartbeat",       "fault_reset",   "window_start", "window_length",
    "window_status", "window_sequence", "window_result", "telemetry",    "calibration"};

}  // namespace

std::string_view name(DeviceKind k) { return kKindNames[static_cast<std::size_t>(k)]; }
std::string_view name(SignalRole r) { return kRoleNames[static_cast<std::size_t>(r)]; }

std::optional<DeviceKind> parse_device_kind(std::string_view s) {
  for (std::size_t i = 0; i < kKindNames.size(); ++i)
    if (kKindNames[i] == s) return static_cast<DeviceKind>(i);
  return std::nullopt;
}

std::span<const SignalSpec> signal_catalogue(DeviceKind k) {
  switch (k) {
    case DeviceKind::synrm_drive: return kSynrm;
    case DeviceKind::load_drive: return kLoad;
    case DeviceKind::vfc_meter: return kMeter;
  }
  return {};
}

const SignalSpec* find_signal_spec(DeviceKind k, std::string_view signal) {
  for (const SignalSpec& s : signal_catalogue(k))
    if (s.name == signal) return &s;
  return nullptr;
}

}  // namespace synbench::drivers
