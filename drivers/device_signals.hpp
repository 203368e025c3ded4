// The device structs of devices.hpp as profile signals: one table per struct saying which
// signal fills which member. The profile drives read and decode through these tables, the
// twin serves its structs through them, so a signal name and its member are written once.
// A member's type says how a signal's number converts to it: double (0 when the profile lacks
// the signal), optional<double> (empty then), bool (non-zero), a count, or an enumerated code.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>
#include <type_traits>
#include <variant>
#include <vector>

#include "drivers/devices.hpp"

namespace synbench::drivers {

template <class S>
using SignalMember = std::variant<double S::*, std::optional<double> S::*, bool S::*, std::uint32_t S::*,
                                  std::uint64_t S::*, DriveState S::*, Fault S::*>;

template <class S>
struct SignalField {
  std::string_view signal;
  SignalMember<S> member;
  // An estimator result of a window: its bit in window_estimates_present (the drive says
  // which results the window has); 0 for every other field.
  unsigned estimate_bit = 0;
};

// Filtered live values: read every supervisor tick.
inline constexpr SignalField<SynrmTelemetry> kSynrmTelemetrySignals[] = {
    {"state", &SynrmTelemetry::state},
    {"fault_code", &SynrmTelemetry::fault},
    {"speed_rpm", &SynrmTelemetry::speed_rpm},
    {"im_A", &SynrmTelemetry::im_A},
    {"id_A", &SynrmTelemetry::id_A},
    {"iq_A", &SynrmTelemetry::iq_A},
    {"ud_V", &SynrmTelemetry::ud_V},
    {"uq_V", &SynrmTelemetry::uq_V},
    {"udc_V", &SynrmTelemetry::udc_V},
    {"pac_W", &SynrmTelemetry::pac_W},
    {"temp_C", &SynrmTelemetry::temp_C},
    {"voltage_limited", &SynrmTelemetry::voltage_limited},
    {"pos_err_deg", &SynrmTelemetry::pos_err_deg},
    {"lock_lost", &SynrmTelemetry::lock_lost},
};

// The device's window results. The reference values (ld_ref_H, ...) are the twin's own and
// have no signal: a drive does not know its flux maps' truth.
inline constexpr SignalField<SynrmWindow> kSynrmWindowSignals[] = {
    {"window_samples", &SynrmWindow::samples},
    {"window_fault_code", &SynrmWindow::fault},
    {"window_s", &SynrmWindow::window_s},
    {"window_speed_meas_rpm", &SynrmWindow::speed_meas_rpm},
    {"window_im_A", &SynrmWindow::im_A},
    {"window_id_A", &SynrmWindow::id_A},
    {"window_iq_A", &SynrmWindow::iq_A},
    {"window_ud_V", &SynrmWindow::ud_V},
    {"window_uq_V", &SynrmWindow::uq_V},
    {"window_udc_V", &SynrmWindow::udc_V},
    {"window_temp_C", &SynrmWindow::temp_C},
    {"window_voltage_limited_fraction", &SynrmWindow::voltage_limited_fraction},
    {"window_fallback_fraction", &SynrmWindow::fallback_fraction},
    {"window_lock_lost_fraction", &SynrmWindow::lock_lost_fraction},
    {"window_pos_err_min_deg", &SynrmWindow::pos_err_min_deg, 1},
    {"window_pos_err_mean_deg", &SynrmWindow::pos_err_mean_deg, 1},
    {"window_pos_err_max_deg", &SynrmWindow::pos_err_max_deg, 1},
    {"window_speed_err_rpm", &SynrmWindow::speed_err_rpm, 1},
    {"window_ld_est_H", &SynrmWindow::ld_est_H, 2},
    {"window_lq_est_H", &SynrmWindow::lq_est_H, 4},
    {"window_rs_est_ohm", &SynrmWindow::rs_est_ohm, 8},
};

// A window the bench keeps (host_window.hpp): the mean of each telemetry signal over the
// polls, into its window member. A bit's mean is the fraction of polls it was set; the
// filtered speed stands in for the encoder-count speed the drive does not report.
inline constexpr SignalField<SynrmWindow> kSynrmHostMeans[] = {
    {"speed_rpm", &SynrmWindow::speed_meas_rpm},
    {"im_A", &SynrmWindow::im_A},
    {"id_A", &SynrmWindow::id_A},
    {"iq_A", &SynrmWindow::iq_A},
    {"ud_V", &SynrmWindow::ud_V},
    {"uq_V", &SynrmWindow::uq_V},
    {"udc_V", &SynrmWindow::udc_V},
    {"temp_C", &SynrmWindow::temp_C},
    {"voltage_limited", &SynrmWindow::voltage_limited_fraction},
    {"lock_lost", &SynrmWindow::lock_lost_fraction},
};

inline constexpr SignalField<LoadTelemetry> kLoadTelemetrySignals[] = {
    {"state", &LoadTelemetry::state},
    {"fault_code", &LoadTelemetry::fault},
    {"torque_Nm", &LoadTelemetry::torque_Nm},
    {"iq_A", &LoadTelemetry::iq_A},
};

inline constexpr SignalField<LoadWindow> kLoadWindowSignals[] = {
    {"window_samples", &LoadWindow::samples},
    {"window_torque_Nm", &LoadWindow::torque_Nm},
};

inline constexpr SignalField<LoadWindow> kLoadHostMeans[] = {
    {"torque_Nm", &LoadWindow::torque_Nm},
};

// The gate's results (meter gate).
inline constexpr SignalField<MeterReading> kMeterGateSignals[] = {
    {"counts_m", &MeterReading::counts_m},
    {"counts_g", &MeterReading::counts_g},
    {"gate_s", &MeterReading::gate_s},
    {"idcm_A", &MeterReading::idcm_A},
    {"idcg_A", &MeterReading::idcg_A},
};

// The calibration a gate meter computes its currents with, read with each gate's results.
inline constexpr SignalField<MeterReading> kMeterCalibrationSignals[] = {
    {"f0_Hz", &MeterReading::f0_Hz},
    {"kf_Hz_per_A", &MeterReading::kf_Hz_per_A},
};

// A power meter's averages, sampled by the bench (meter power).
inline constexpr SignalField<MeterReading> kMeterPowerMeans[] = {
    {"pdcm_W", &MeterReading::pdcm_W},
    {"pdcg_W", &MeterReading::pdcg_W},
};

// Array signals (a profile's "count"): a window's batches, one value per sub-window.
template <class S>
using ArrayMember = std::variant<std::vector<double> S::*, std::vector<std::uint64_t> S::*>;

template <class S>
struct ArrayField {
  std::string_view signal;
  ArrayMember<S> member;
};

inline constexpr ArrayField<SynrmWindow> kSynrmWindowArrays[] = {
    {"window_batch_im_A", &SynrmWindow::batch_im_A},
    {"window_batch_speed_meas_rpm", &SynrmWindow::batch_speed_meas_rpm},
};

inline constexpr ArrayField<LoadWindow> kLoadWindowArrays[] = {
    {"window_batch_torque_Nm", &LoadWindow::batch_torque_Nm},
};

inline constexpr ArrayField<MeterReading> kMeterGateArrays[] = {
    {"batch_counts_m", &MeterReading::batch_counts_m},
    {"batch_counts_g", &MeterReading::batch_counts_g},
};

// A window the bench keeps: the telemetry signal whose polls, split into batches by time, give
// each batch member (host_window.hpp).
inline constexpr ArrayField<SynrmWindow> kSynrmHostBatches[] = {
    {"im_A", &SynrmWindow::batch_im_A},
    {"speed_rpm", &SynrmWindow::batch_speed_meas_rpm},
};

inline constexpr ArrayField<LoadWindow> kLoadHostBatches[] = {
    {"torque_Nm", &LoadWindow::batch_torque_Nm},
};

// Sets an array member from the signal's values (counts rounded to whole pulses).
template <class S>
void assign(S& out, const ArrayMember<std::type_identity_t<S>>& member, const std::vector<double>& v) {
  std::visit(
      [&](auto m) {
        auto& field = out.*m;
        using T = typename std::remove_reference_t<decltype(field)>::value_type;
        field.clear();
        for (double x : v) field.push_back(std::is_same_v<T, double> ? static_cast<T>(x) : static_cast<T>(std::llround(x)));
      },
      member);
}

// The array member as the signal's numbers.
template <class S>
std::vector<double> numbers(const S& in, const ArrayMember<std::type_identity_t<S>>& member) {
  return std::visit(
      [&](auto m) {
        std::vector<double> v;
        for (const auto x : in.*m) v.push_back(static_cast<double>(x));
        return v;
      },
      member);
}

template <class S, std::size_t N>
const SignalField<S>* find_field(const SignalField<S> (&table)[N], std::string_view signal) {
  for (const SignalField<S>& f : table)
    if (f.signal == signal) return &f;
  return nullptr;
}

template <class S, std::size_t N>
const ArrayField<S>* find_array(const ArrayField<S> (&table)[N], std::string_view signal) {
  for (const ArrayField<S>& f : table)
    if (f.signal == signal) return &f;
  return nullptr;
}

// Sets the member from a signal's number; NaN is a signal the profile does not map.
template <class S>
void assign(S& out, const SignalMember<std::type_identity_t<S>>& member, double v) {
  std::visit(
      [&](auto m) {
        auto& field = out.*m;
        using T = std::remove_reference_t<decltype(field)>;
        const bool absent = std::isnan(v);
        if constexpr (std::is_same_v<T, std::optional<double>>)
          field = absent ? std::nullopt : std::optional<double>(v);
        else if constexpr (std::is_same_v<T, double>)
          field = absent ? 0.0 : v;
        else if constexpr (std::is_same_v<T, bool>)
          field = !absent && v != 0;
        else if constexpr (std::is_enum_v<T>)
          field = static_cast<T>(absent ? 0 : static_cast<int>(v));
        else
          field = absent ? T{0} : static_cast<T>(v);
      },
      member);
}

// The member as a signal's number (enumerated codes as the bench's, bits as 0 or 1); empty
// for an empty optional.
template <class S>
std::optional<double> number(const S& in, const SignalMember<std::type_identity_t<S>>& member) {
  return std::visit(
      [&](auto m) -> std::optional<double> {
        const auto& field = in.*m;
        using T = std::remove_cvref_t<decltype(field)>;
        if constexpr (std::is_same_v<T, std::optional<double>>)
          return field;
        else if constexpr (std::is_enum_v<T>)
          return static_cast<double>(static_cast<int>(field));
        else
          return static_cast<double>(field);
      },
      member);
}

// Which estimator results `w` has, as window_estimates_present's bits.
inline unsigned estimates_present(const SynrmWindow& w) {
  unsigned bits = 0;
  for (const auto& f : kSynrmWindowSignals)
    if (f.estimate_bit && number(w, f.member)) bits |= f.estimate_bit;
  return bits;
}

}  // namespace synbench::drivers
