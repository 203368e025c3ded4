// Window results no window can have.
#include "bench/window_plausibility.hpp"

#include <cmath>
#include <cstdio>

#include "drivers/printf_text.hpp"

namespace synbench::bench {
namespace {

// A current magnitude's own rounding in a register (and a third-party drive's offset).
constexpr double kMagnitudeTolerance_A = 0.01;
// As for the live telemetry (telemetry_plausibility.hpp): a lab winding sensor's range.
constexpr double kMinTemp_C = -30.0, kMaxTemp_C = 250.0;
constexpr double kMinUdc_V = -5.0;

std::string say(const char* field, const std::string& text) { return std::string(field) + ": " + text; }

}  // namespace

std::optional<std::string> implausible_window(const drivers::SynrmWindow& w, const drivers::LoadWindow& load,
                                              const drivers::MeterReading& meter) {
  const struct {
    const char* field;
    double value;
  } finite[] = {
      {"window_s", w.window_s},         {"window_speed_meas_rpm", w.speed_meas_rpm},
      {"window_im_A", w.im_A},          {"window_id_A", w.id_A},
      {"window_iq_A", w.iq_A},          {"window_ud_V", w.ud_V},
      {"window_uq_V", w.uq_V},          {"window_udc_V", w.udc_V},
      {"window_voltage_limited_fraction", w.voltage_limited_fraction},
      {"window_fallback_fraction", w.fallback_fraction}, {"window_lock_lost_fraction", w.lock_lost_fraction},
      {"window_torque_Nm", load.torque_Nm}, {"gate_s", meter.gate_s},
      {"idcm_A", meter.idcm_A},         {"idcg_A", meter.idcg_A},
  };
  for (const auto& f : finite)
    if (!std::isfinite(f.value)) return say(f.field, drivers::printf_text("%g is not a finite number", f.value));
  for (const auto& [field, value] : {std::pair{"pdcm_W", meter.pdcm_W}, std::pair{"pdcg_W", meter.pdcg_W}})
    if (value && !std::isfinite(*value)) return say(field, drivers::printf_text("%g is not a finite number", *value));
  const struct {
    const char* field;
    const std::optional<double>& value;
  } estimates[] = {
      {"window_pos_err_min_deg", w.pos_err_min_deg}, {"window_pos_err_mean_deg", w.pos_err_mean_deg},
      {"window_pos_err_max_deg", w.pos_err_max_deg}, {"window_speed_err_rpm", w.speed_err_rpm},
      {"window_ld_est_H", w.ld_est_H},               {"window_lq_est_H", w.lq_est_H},
      {"window_rs_est_ohm", w.rs_est_ohm},           {"window_temp_C", w.temp_C},
  };
  for (const auto& e : estimates)
    if (e.value && !std::isfinite(*e.value)) return say(e.field, drivers::printf_text("%g is not a finite number", *e.value));

  if (w.samples == 0) return std::string("window_samples: 0, a window without samples");
  // Too few samples to be a mean: a window of one control period reads the instant's speed
  // (0 rpm at a 300 rpm setpoint) and its efficiency as a measurement (docs/record.md).
  if (const std::uint32_t least = min_window_samples(w.keeper); w.samples < least)
    return "window_samples: " + std::to_string(w.samples) + ", fewer than the " + std::to_string(least) + " a " +
           (w.keeper == drivers::WindowKeeper::host ? "host-kept window's polls" : "drive's window") + " must hold to be a mean";
  if (!(w.window_s > 0)) return say("window_s", drivers::printf_text("%g s: a window has a length", w.window_s));
  if (w.im_A < -kMagnitudeTolerance_A)
    return say("window_im_A", drivers::printf_text("%g A is negative: it is the mean of a current magnitude", w.im_A));
  // The mean of a vector's magnitude is never less than the magnitude of its mean (the
  // triangle inequality): an I_m below hypot(I_d, I_q) was not measured with them.
  const double im_min = std::hypot(w.id_A, w.iq_A) * (1 - 1e-3) - kMagnitudeTolerance_A;
  if (w.im_A < im_min)
    return say("window_im_A", drivers::printf_text("%g A is less than the magnitude of the window's mean (I_d, I_q), %g A", w.im_A,
               std::hypot(w.id_A, w.iq_A)));
  if (w.udc_V < kMinUdc_V) return say("window_udc_V", drivers::printf_text("%g V is negative: the DC bus never reverses", w.udc_V));
  if (w.temp_C && (*w.temp_C < kMinTemp_C || *w.temp_C > kMaxTemp_C))
    return say("window_temp_C", drivers::printf_text("%g degC is outside a winding's [-30, 250] degC", *w.temp_C));
  const struct {
    const char* field;
    double value;
  } fractions[] = {{"window_voltage_limited_fraction", w.voltage_limited_fraction},
                   {"window_fallback_fraction", w.fallback_fraction},
                   {"window_lock_lost_fraction", w.lock_lost_fraction}};
  for (const auto& f : fractions)
    if (f.value < -1e-6 || f.value > 1 + 1e-6) return say(f.field, drivers::printf_text("%g is not a fraction in [0, 1]", f.value));
  if (meter.gate_s < 0) return say("gate_s", drivers::printf_text("%g s is negative", meter.gate_s));
  return std::nullopt;
}

std::optional<std::string> window_timing_mismatch(const drivers::SynrmWindow& w, const drivers::LoadWindow& load,
                                                  const drivers::MeterReading& meter, double requested_s,
                                                  double jitter_s) {
  using drivers::WindowKeeper;
  const struct {
    const char* who;
    bool host;
    double span_s;
    const drivers::HostSampling& sampling;
  } sources[] = {
      {"the SynRM drive's host samples", w.keeper == WindowKeeper::host, w.window_s, w.host},
      {"the load drive's host samples", load.keeper == WindowKeeper::host, load.window_s, load.host},
      {"the power meter's host samples", meter.keeper == WindowKeeper::host, meter.gate_s, meter.host},
  };
  // The meter's own time base, where it keeps one (a gate or a totalizer's time-base counter).
  const bool meter_clock = meter.keeper == WindowKeeper::device && meter.gate_s > 0;
  char buf[320];
  for (const auto& s : sources) {
    if (!s.host) continue;
    const double tolerance_s = s.sampling.poll_period_s + jitter_s;
    if (meter_clock && std::fabs(s.span_s - meter.gate_s) > tolerance_s) {
      std::snprintf(buf, sizeof buf,
                    "window: %.4g s by %s but %.4g s by the meter's time base (tolerance %.3g s: one poll period and "
                    "%.3g s of jitter): the powers would come from different spans",
                    s.span_s, s.who, meter.gate_s, tolerance_s, jitter_s);
      return std::string(buf);
    }
    if (std::fabs(s.span_s - requested_s) > tolerance_s) {
      std::snprintf(buf, sizeof buf,
                    "window: %.4g s by %s but %.4g s asked (tolerance %.3g s; longest gap between samples %.3g s): "
                    "the bench did not poll the window to its end on time",
                    s.span_s, s.who, requested_s, tolerance_s, s.sampling.longest_gap_s);
      return std::string(buf);
    }
  }
  return std::nullopt;
}

std::optional<std::string> implausible_powers(const PointRecord& r) {
  char buf[240];
  if (r.pm_W > 0 && r.pdcm_W <= 0) {
    std::snprintf(buf, sizeof buf, "pm_W: %.4g W of mechanical output with pdcm_W %.4g W of electrical input", r.pm_W,
                  r.pdcm_W);
    return std::string(buf);
  }
  if (r.pm_W > 0 && r.pm_W > r.pdcm_W) {
    std::snprintf(buf, sizeof buf,
                  "efficiency: %.4g > 1: pm_W %.4g W exceeds pdcm_W %.4g W while motoring (a motor puts out less "
                  "than it takes in)",
                  r.pm_W / r.pdcm_W, r.pm_W, r.pdcm_W);
    return std::string(buf);
  }
  return std::nullopt;
}

}  // namespace synbench::bench
