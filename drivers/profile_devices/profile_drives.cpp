// Typed devices over profile signals.
#include "drivers/profile_devices/profile_drives.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "drivers/error.hpp"
#include "drivers/frozen_watch.hpp"

namespace synbench::drivers {
namespace {

// NaN (signal absent from the profile) reads as `absent`.
double or_(double v, double absent = 0.0) { return std::isnan(v) ? absent : v; }
std::optional<double> opt(double v) { return std::isnan(v) ? std::nullopt : std::optional<double>(v); }

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
      telemetry_(this->profile(), {"state", "fault_code", "speed_rpm", "im_A", "id_A", "iq_A", "ud_V",
                                   "uq_V", "udc_V", "pac_W", "temp_C", "voltage_limited", "pos_err_deg", "lock_lost"}),
      window_(this->profile(),
              {"window_status", "window_sequence", "window_samples", "window_fault_code", "window_s",
               "window_speed_meas_rpm", "window_im_A", "window_id_A", "window_iq_A", "window_ud_V",
               "window_uq_V", "window_udc_V", "window_temp_C", "window_voltage_limited_fraction",
               "window_fallback_fraction", "window_lock_lost_fraction"}),
      estimator_window_(this->profile(),
                        {"window_pos_err_min_deg", "window_pos_err_mean_deg", "window_pos_err_max_deg",
                         "window_speed_err_rpm", "window_ld_est_H", "window_lq_est_H",
                         "window_rs_est_ohm", "window_estimates_present"}),
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
  double v[14];
  if (auto ec = io().read(telemetry_, v)) return ec;
  out.state = static_cast<DriveState>(static_cast<int>(v[0]));
  out.fault = static_cast<Fault>(static_cast<int>(v[1]));
  out.fault_code_raw = raw_code(out.fault, telemetry_.device_value(1));
  out.speed_rpm = v[2];
  out.im_A = or_(v[3]);
  out.id_A = or_(v[4]);
  out.iq_A = or_(v[5]);
  out.ud_V = or_(v[6]);
  out.uq_V = or_(v[7]);
  out.udc_V = or_(v[8]);
  out.pac_W = or_(v[9]);
  out.temp_C = opt(v[10]);
  out.voltage_limited = or_(v[11]) != 0;
  // The register reads 0 with the encoder and on the lock guard; a profile without it leaves the
  // field empty.
  out.lock_lost = or_(v[13]) != 0;
  out.pos_err_deg = estimator_ != Estimator::encoder && !out.lock_lost ? opt(v[12]) : std::nullopt;
  return {};
}

std::error_code ProfileSynrmDrive::read_window(SynrmWindow& out) {
  if (host_) return read_host_window(out);
  double v[16];
  if (auto ec = window().read_results(window_, v)) return ec;
  SynrmWindow w;
  w.samples = static_cast<std::uint32_t>(v[2]);
  w.fault = static_cast<Fault>(static_cast<int>(or_(v[3])));
  w.fault_code_raw = raw_code(w.fault, window_.device_value(3));
  w.window_s = v[4];
  w.speed_meas_rpm = or_(v[5]);
  w.im_A = or_(v[6]);
  w.id_A = or_(v[7]);
  w.iq_A = or_(v[8]);
  w.ud_V = or_(v[9]);
  w.uq_V = or_(v[10]);
  w.udc_V = or_(v[11]);
  w.temp_C = opt(v[12]);
  w.voltage_limited_fraction = or_(v[13]);
  w.fallback_fraction = or_(v[14]);
  w.lock_lost_fraction = or_(v[15]);
  if (estimator_ != Estimator::encoder) {
    // Read after the sequence check: the next window cannot open before this bench starts it.
    double e[8];
    if (auto ec = io().read(estimator_window_, e)) return ec;
    // A register holds a number: the drive says which fields it has (a window wholly on the lock
    // guard has no errors; EEMF-CONST no estimates). Without the signal, all are present.
    const unsigned present = std::isnan(e[7]) ? 15u : static_cast<unsigned>(e[7]);
    const auto field = [present](double raw, unsigned bit) { return present & bit ? opt(raw) : std::nullopt; };
    w.pos_err_min_deg = field(e[0], 1);
    w.pos_err_mean_deg = field(e[1], 1);
    w.pos_err_max_deg = field(e[2], 1);
    w.speed_err_rpm = field(e[3], 1);
    w.ld_est_H = field(e[4], 2);
    w.lq_est_H = field(e[5], 4);
    w.rs_est_ohm = field(e[6], 8);
  }
  out = w;
  return {};
}

// The window the bench kept from the telemetry plan's samples (indices as in read()). The
// filtered telemetry is all there is: no encoder-count speed (the mean of speed_rpm stands in),
// no Ld/Lq/Rs estimates, position errors only when the drive reports pos_err_deg live.
std::error_code ProfileSynrmDrive::read_host_window(SynrmWindow& out) {
  if (auto ec = host_->result()) return ec;
  const HostWindow& h = *host_;
  SynrmWindow w;
  w.keeper = WindowKeeper::host;
  w.samples = h.samples();
  w.window_s = h.span_s();
  w.fault = static_cast<Fault>(static_cast<int>(h.first_nonzero(1)));
  w.fault_code_raw = raw_code(w.fault, h.first_nonzero_device(1));
  w.host = {h.period_s(), h.longest_gap_s()};
  w.speed_meas_rpm = h.mean(2);
  w.im_A = or_(h.mean(3));
  w.id_A = or_(h.mean(4));
  w.iq_A = or_(h.mean(5));
  w.ud_V = or_(h.mean(6));
  w.uq_V = or_(h.mean(7));
  w.udc_V = or_(h.mean(8));
  w.temp_C = opt(h.mean(10));
  w.voltage_limited_fraction = or_(h.mean(11));
  w.lock_lost_fraction = or_(h.mean(13));
  if (estimator_ != Estimator::encoder && telemetry_.present(12)) {
    w.pos_err_min_deg = h.min(12);
    w.pos_err_mean_deg = h.mean(12);
    w.pos_err_max_deg = h.max(12);
  }
  out = w;
  return {};
}

// --- Load drive ----------------------------------------------------------------------------

ProfileLoadDrive::ProfileLoadDrive(RegisterBus& bus, DeviceProfile profile)
    : ProfileDevice(bus, (require_kind(profile, DeviceKind::load_drive), std::move(profile))),
      telemetry_(this->profile(), {"state", "fault_code", "torque_Nm", "iq_A"}),
      window_(this->profile(), {"window_status", "window_sequence", "window_samples", "window_torque_Nm"}),
      host_(host_window_over(telemetry_)) {}

std::error_code ProfileLoadDrive::enable(bool on) { return io().write("enable", on ? 1 : 0); }
std::error_code ProfileLoadDrive::disable_once() { return io().write_once("enable", 0); }
std::error_code ProfileLoadDrive::set_torque_Nm(double v) { return io().write("torque_setpoint_Nm", v); }
std::error_code ProfileLoadDrive::reset_fault() { return pulse_fault_reset(); }

std::error_code ProfileLoadDrive::read(LoadTelemetry& out) {
  double v[4];
  if (auto ec = io().read(telemetry_, v)) return ec;
  out.state = static_cast<DriveState>(static_cast<int>(v[0]));
  out.fault = static_cast<Fault>(static_cast<int>(v[1]));
  out.fault_code_raw = raw_code(out.fault, telemetry_.device_value(1));
  out.torque_Nm = v[2];
  out.iq_A = or_(v[3]);
  return {};
}

std::error_code ProfileLoadDrive::read_window(LoadWindow& out) {
  if (host_) {
    if (auto ec = host_->result()) return ec;
    LoadWindow w;
    w.keeper = WindowKeeper::host;
    w.samples = host_->samples();
    w.torque_Nm = host_->mean(2);
    w.window_s = host_->span_s();
    w.host = {host_->period_s(), host_->longest_gap_s()};
    out = w;
    return {};
  }
  double v[4];
  if (auto ec = window().read_results(window_, v)) return ec;
  out.samples = static_cast<std::uint32_t>(or_(v[2]));
  out.torque_Nm = or_(v[3]);
  return {};
}

// --- VFC meter -----------------------------------------------------------------------------

ProfileMeter::ProfileMeter(RegisterBus& bus, DeviceProfile profile)
    : ProfileDevice(bus, (require_kind(profile, DeviceKind::vfc_meter), std::move(profile))),
      gate_(this->profile(), {"gate_status", "gate_sequence", "counts_m", "counts_g", "gate_s", "idcm_A", "idcg_A"}),
      power_(this->profile(), {"pdcm_W", "pdcg_W"}) {
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
  if (host_) {
    if (auto ec = host_->result()) return ec;
    MeterReading m;
    m.keeper = WindowKeeper::host;
    m.samples = host_->samples();
    m.gate_s = host_->span_s();
    m.pdcm_W = host_->mean(0);
    m.pdcg_W = host_->mean(1);
    m.host = {host_->period_s(), host_->longest_gap_s()};
    out = m;
    return {};
  }
  double v[7];
  if (auto ec = window().read_results(gate_, v)) return ec;
  out.counts_m = static_cast<std::uint64_t>(or_(v[2]));
  out.counts_g = static_cast<std::uint64_t>(or_(v[3]));
  out.gate_s = or_(v[4]);
  out.idcm_A = or_(v[5]);
  out.idcg_A = or_(v[6]);
  return {};
}

}  // namespace synbench::drivers
