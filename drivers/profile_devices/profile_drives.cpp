// Typed devices over profile signals: reads planned, decoded and averaged through the device
// structs' signal tables (drivers/device_signals.hpp), never by position.
#include "drivers/profile_devices/profile_drives.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "drivers/device_signals.hpp"
#include "drivers/error.hpp"
#include "drivers/frozen_watch.hpp"

namespace synbench::drivers {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Which fields of a table a plan holds (the estimator results are read only with an estimator).
constexpr auto every = [](const auto&) { return true; };
constexpr auto is_estimate = [](const auto& f) { return f.estimate_bit != 0; };
constexpr auto not_estimate = [](const auto& f) { return f.estimate_bit == 0; };

// The signal names of a read plan: `lead` (a window's status and sequence, which
// WindowChannel::read_results wants first), then the table's fields that `keep` accepts.
template <class S, std::size_t N, class Keep = decltype(every)>
std::vector<std::string_view> names_of(const SignalField<S> (&table)[N], std::vector<std::string_view> lead = {},
                                       Keep keep = every) {
  for (const SignalField<S>& f : table)
    if (keep(f)) lead.push_back(f.signal);
  return lead;
}

// The plan's value of `signal` (NaN when the plan has no such name or the profile lacks it).
double value_of(const ReadPlan& plan, std::span<const double> values, std::string_view signal) {
  const std::size_t i = plan.index(signal);
  return i < plan.size() ? values[i] : kNaN;
}

// Every field of `table` the plan holds, from the values read; the plan's own other names
// (status, sequence) are left alone, fields it lacks read as absent.
template <class S, std::size_t N, class Keep = decltype(every)>
void assign_read(S& out, const SignalField<S> (&table)[N], const ReadPlan& plan, std::span<const double> values,
                 Keep keep = every) {
  for (const SignalField<S>& f : table)
    if (keep(f)) assign(out, f.member, value_of(plan, values, f.signal));
}

// The mean over a host window of each table signal into its member.
template <class S, std::size_t N>
void assign_means(S& out, const SignalField<S> (&table)[N], const ReadPlan& plan, const HostWindow& h) {
  for (const SignalField<S>& f : table) {
    const std::size_t i = plan.index(f.signal);
    assign(out, f.member, i < plan.size() ? h.mean(i) : kNaN);
  }
}

// The plan's names and every array signal of `arrays` after them (read in the same requests
// where the map puts them next to the others).
template <class S>
std::vector<std::string_view> with_arrays(std::vector<std::string_view> names, std::span<const ArrayField<S>> arrays) {
  for (const ArrayField<S>& f : arrays) names.push_back(f.signal);
  return names;
}

// Every array of `arrays` the plan holds, from its last read; those it lacks stay empty, and so
// does an array of zeros: a window the device kept no batches of (shorter than its batches).
template <class S>
std::error_code assign_arrays(S& out, std::span<const ArrayField<S>> arrays, const ReadPlan& plan, SignalIo& io) {
  for (const ArrayField<S>& f : arrays) {
    if (!plan.present(f.signal)) continue;
    std::vector<double> v;
    if (auto ec = io.read_array(plan, f.signal, v)) return ec;
    if (std::any_of(v.begin(), v.end(), [](double x) { return x != 0; })) assign(out, f.member, v);
  }
  return {};
}

// The batch means a host window kept of each telemetry signal into its array member (empty
// when the window had too few polls for batches).
template <class S>
void assign_host_batches(S& out, std::span<const ArrayField<S>> batches, const ReadPlan& plan, const HostWindow& h) {
  for (const ArrayField<S>& f : batches) {
    const std::size_t i = plan.index(f.signal);
    if (plan.present(i)) assign(out, f.member, h.batch_means(i));
  }
}

// What every host-kept window reports of its own keeping.
template <class W>
void keep_by_host(W& w, const HostWindow& h) {
  w.keeper = WindowKeeper::host;
  w.samples = h.samples();
  w.host = {h.period_s(), h.longest_gap_s()};
}

// A window's result from the means the host kept over `polled` (its span into `span`), or
// else from the device's own window registers: the choice every profile device but the
// SynRM drive (which has more to read) makes the same way.
template <class W, std::size_t NM, std::size_t NR>
std::error_code read_window_result(W& out, const HostWindow* host, double W::*span,
                                   const SignalField<W> (&means)[NM], std::span<const ArrayField<W>> batches,
                                   const ReadPlan& polled, const SignalField<W> (&registers)[NR],
                                   std::span<const ArrayField<W>> arrays, const ReadPlan& plan,
                                   WindowChannel& channel, SignalIo& io) {
  W w;
  if (host) {
    if (auto ec = host->result()) return ec;
    keep_by_host(w, *host);
    w.*span = host->span_s();
    assign_means(w, means, polled, *host);
    assign_host_batches(w, batches, polled, *host);
  } else {
    std::vector<double> v(plan.size());
    if (auto ec = channel.read_results(plan, v)) return ec;
    assign_read(w, registers, plan, v);
    if (auto ec = assign_arrays(w, arrays, plan, io)) return ec;
  }
  out = w;
  return {};
}

// The device's own code behind a fault the profile has no label for.
std::optional<std::int64_t> raw_code(Fault f, double device_value) {
  if (f != Fault::unknown || std::isnan(device_value)) return std::nullopt;
  return static_cast<std::int64_t>(device_value);
}

void require_kind(const DeviceProfile& p, DeviceKind kind) {
  if (p.kind != kind)
    throw std::invalid_argument("profile '" + p.name + "' is of kind " + std::string(name(p.kind)) +
                                ", not " + std::string(name(kind)));
}

}  // namespace

ProfileDevice::ProfileDevice(RegisterBus& bus, DeviceProfile profile)
    : profile_(std::move(profile)), io_(bus, profile_), heartbeat_(profile_), window_(io_) {}

std::error_code ProfileDevice::pulse_fault_reset() {
  const ProfileSignal* s = profile_.find("fault_reset");
  auto ec = io_.write("fault_reset", 1);
  if (!ec && s && s->reset.mode == FaultResetMode::Mode::pulse) {
    // Held from the next tick on: logic never sleeps, the bench's clock ends the pulse.
    reset_held_ = true;
    reset_clear_s_ = std::numeric_limits<double>::quiet_NaN();
  }
  return ec;
}

std::error_code ProfileDevice::tick(double now_s, bool feed_watchdog) {
  std::error_code ec;
  if (reset_held_) {
    const ProfileSignal* s = profile_.find("fault_reset");
    if (std::isnan(reset_clear_s_)) reset_clear_s_ = now_s + s->reset.pulse_ms / 1000.0;
    if (now_s >= reset_clear_s_ - 1e-9) {
      ec = io_.write("fault_reset", 0);
      if (!ec)
        reset_held_ = false;
      else
        reset_clear_s_ = now_s + 0.01;  // tried again soon; a held reset blocks nothing else
    }
  }
  if (feed_watchdog)
    if (auto e = heartbeat_.tick(now_s, io_); e && !ec) ec = e;
  return ec;
}

double ProfileDevice::next_heartbeat_s(bool feed_watchdog) const {
  const double reset = !reset_held_ ? std::numeric_limits<double>::infinity()
                       : std::isnan(reset_clear_s_) ? -std::numeric_limits<double>::infinity()
                                                    : reset_clear_s_;
  return std::min(reset, feed_watchdog ? heartbeat_.next_due_s() : std::numeric_limits<double>::infinity());
}

HostWindow* ProfileDevice::host_window_over(const ReadPlan& plan) {
  if (!profile_.poll_period_ms) return nullptr;
  auto w = std::make_unique<HostWindow>(io_, plan, *profile_.poll_period_ms / 1000.0);
  HostWindow* raw = w.get();
  set_window_source(std::move(w));
  return raw;
}

// --- SynRM drive ---------------------------------------------------------------------------

ProfileSynrmDrive::ProfileSynrmDrive(RegisterBus& bus, DeviceProfile profile)
    : ProfileDevice(bus, (require_kind(profile, DeviceKind::synrm_drive), std::move(profile))),
      telemetry_(this->profile(), names_of(kSynrmTelemetrySignals)),
      window_(this->profile(), with_arrays(names_of(kSynrmWindowSignals, {"window_status", "window_sequence"}, not_estimate),
                                           std::span<const ArrayField<SynrmWindow>>(kSynrmWindowArrays))),
      estimator_window_(this->profile(), names_of(kSynrmWindowSignals, {"window_estimates_present"}, is_estimate)),
      host_(host_window_over(telemetry_)) {}

std::error_code ProfileSynrmDrive::enable(bool on) { return io().write("enable", on ? 1 : 0); }
std::error_code ProfileSynrmDrive::disable_once() { return io().write_once("enable", 0); }
std::error_code ProfileSynrmDrive::set_speed_rpm(double v) { return io().write("speed_setpoint_rpm", v); }
std::error_code ProfileSynrmDrive::set_angle_deg(double v) { return io().write("angle_setpoint_deg", v); }
std::error_code ProfileSynrmDrive::reset_fault() { return pulse_fault_reset(); }

std::error_code ProfileSynrmDrive::set_pwm(Pwm pwm) {
  if (!io().has("pwm_scheme"))
    return pwm == Pwm::capwm ? std::error_code{} : make_error_code(errc::not_supported);
  return io().write("pwm_scheme", static_cast<double>(pwm));
}

std::error_code ProfileSynrmDrive::set_estimator(Estimator estimator) {
  std::error_code ec;
  if (!io().has("estimator")) {
    if (estimator != Estimator::encoder) ec = make_error_code(errc::not_supported);
  } else {
    ec = io().write("estimator", static_cast<double>(estimator));
  }
  if (!ec) estimator_ = estimator;
  return ec;
}

TelemetryResolution ProfileSynrmDrive::resolution() const { return telemetry_resolution(profile()); }

std::error_code ProfileSynrmDrive::read(SynrmTelemetry& out) {
  std::vector<double> v(telemetry_.size());
  if (auto ec = io().read(telemetry_, v)) return ec;
  SynrmTelemetry t;
  assign_read(t, kSynrmTelemetrySignals, telemetry_, v);
  t.fault_code_raw = raw_code(t.fault, telemetry_.device_value(telemetry_.index("fault_code")));
  // The register reads 0 with the encoder and on the lock guard; a profile without it leaves the
  // field empty.
  if (estimator_ == Estimator::encoder || t.lock_lost) t.pos_err_deg.reset();
  out = t;
  return {};
}

std::error_code ProfileSynrmDrive::read_window(SynrmWindow& out) {
  if (host_) return read_host_window(out);
  std::vector<double> v(window_.size());
  if (auto ec = window().read_results(window_, v)) return ec;
  SynrmWindow w;
  assign_read(w, kSynrmWindowSignals, window_, v, not_estimate);
  if (auto ec = assign_arrays(w, std::span<const ArrayField<SynrmWindow>>(kSynrmWindowArrays), window_, io())) return ec;
  w.fault_code_raw = raw_code(w.fault, window_.device_value(window_.index("window_fault_code")));
  if (estimator_ != Estimator::encoder) {
    // Read after the sequence check: the next window cannot open before this bench starts it.
    std::vector<double> e(estimator_window_.size());
    if (auto ec = io().read(estimator_window_, e)) return ec;
    // A register holds a number: the drive says which fields it has (a window wholly on the lock
    // guard has no errors; EEMF-CONST no estimates). Without the signal, all are present.
    const double bits = value_of(estimator_window_, e, "window_estimates_present");
    const unsigned present = std::isnan(bits) ? ~0u : static_cast<unsigned>(bits);
    for (const auto& f : kSynrmWindowSignals)
      if (f.estimate_bit)
        assign(w, f.member, present & f.estimate_bit ? value_of(estimator_window_, e, f.signal) : kNaN);
  }
  out = w;
  return {};
}

// The window the bench kept from the telemetry plan's samples. The filtered telemetry is all
// there is: no encoder-count speed (kSynrmHostMeans), no Ld/Lq/Rs estimates, position errors
// only when the drive reports pos_err_deg live.
std::error_code ProfileSynrmDrive::read_host_window(SynrmWindow& out) {
  if (auto ec = host_->result()) return ec;
  const HostWindow& h = *host_;
  SynrmWindow w;
  keep_by_host(w, h);
  w.window_s = h.span_s();
  const std::size_t fault = telemetry_.index("fault_code");
  assign(w, &SynrmWindow::fault, h.first_nonzero(fault));
  w.fault_code_raw = raw_code(w.fault, h.first_nonzero_device(fault));
  assign_means(w, kSynrmHostMeans, telemetry_, h);
  assign_host_batches(w, std::span<const ArrayField<SynrmWindow>>(kSynrmHostBatches), telemetry_, h);
  const std::size_t pos_err = telemetry_.index("pos_err_deg");
  if (estimator_ != Estimator::encoder && telemetry_.present(pos_err)) {
    w.pos_err_min_deg = h.min(pos_err);
    w.pos_err_mean_deg = h.mean(pos_err);
    w.pos_err_max_deg = h.max(pos_err);
  }
  out = w;
  return {};
}

// --- Load drive ----------------------------------------------------------------------------

ProfileLoadDrive::ProfileLoadDrive(RegisterBus& bus, DeviceProfile profile)
    : ProfileDevice(bus, (require_kind(profile, DeviceKind::load_drive), std::move(profile))),
      telemetry_(this->profile(), names_of(kLoadTelemetrySignals)),
      window_(this->profile(), with_arrays(names_of(kLoadWindowSignals, {"window_status", "window_sequence"}),
                                           std::span<const ArrayField<LoadWindow>>(kLoadWindowArrays))),
      host_(host_window_over(telemetry_)) {}

std::error_code ProfileLoadDrive::enable(bool on) { return io().write("enable", on ? 1 : 0); }
std::error_code ProfileLoadDrive::disable_once() { return io().write_once("enable", 0); }
std::error_code ProfileLoadDrive::set_torque_Nm(double v) { return io().write("torque_setpoint_Nm", v); }
std::error_code ProfileLoadDrive::reset_fault() { return pulse_fault_reset(); }

std::error_code ProfileLoadDrive::read(LoadTelemetry& out) {
  std::vector<double> v(telemetry_.size());
  if (auto ec = io().read(telemetry_, v)) return ec;
  LoadTelemetry t;
  assign_read(t, kLoadTelemetrySignals, telemetry_, v);
  t.fault_code_raw = raw_code(t.fault, telemetry_.device_value(telemetry_.index("fault_code")));
  out = t;
  return {};
}

std::error_code ProfileLoadDrive::read_window(LoadWindow& out) {
  return read_window_result(out, host_, &LoadWindow::window_s, kLoadHostMeans,
                            std::span<const ArrayField<LoadWindow>>(kLoadHostBatches), telemetry_, kLoadWindowSignals,
                            std::span<const ArrayField<LoadWindow>>(kLoadWindowArrays), window_, window(), io());
}

// --- VFC meter -----------------------------------------------------------------------------

ProfileMeter::ProfileMeter(RegisterBus& bus, DeviceProfile profile)
    : ProfileDevice(bus, (require_kind(profile, DeviceKind::vfc_meter), std::move(profile))),
      gate_(this->profile(), with_arrays(names_of(kMeterGateSignals, {"gate_status", "gate_sequence"}),
                                         std::span<const ArrayField<MeterReading>>(kMeterGateArrays))),
      power_(this->profile(), names_of(kMeterPowerMeans)),
      calibration_(this->profile(), names_of(kMeterCalibrationSignals)) {
  switch (this->profile().meter) {
    case MeterKind::gate: break;
    case MeterKind::totalizer: {
      auto t = std::make_unique<TotalizerWindow>(io());
      totalizer_ = t.get();
      set_window_source(std::move(t));
      break;
    }
    case MeterKind::power: host_ = host_window_over(power_); break;
  }
}

std::error_code ProfileMeter::read(MeterReading& out) {
  if (totalizer_) return totalizer_->read(out);
  // A power meter's polls keep no batches: MeterReading has batches of VFC counts only.
  MeterReading m;
  if (auto ec = read_window_result(m, host_, &MeterReading::gate_s, kMeterPowerMeans, {}, power_, kMeterGateSignals,
                                   std::span<const ArrayField<MeterReading>>(kMeterGateArrays), gate_, window(), io()))
    return ec;
  // A gate's currents come from the meter's calibration: the nominal f0 and Kf with them (a
  // profile without the calibration signals leaves them 0).
  if (!host_ && calibration_.requests() > 0) {
    std::vector<double> v(calibration_.size());
    if (auto ec = io().read(calibration_, v)) return ec;
    assign_read(m, kMeterCalibrationSignals, calibration_, v);
  }
  out = m;
  return {};
}

}  // namespace synbench::drivers
