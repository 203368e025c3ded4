// Parameter table of the twin and the loader, validator and documenter driven by it.
#include "emulator/twin_config_schema.hpp"

#include "drivers/json.hpp"

#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <utility>

#include "drivers/json_file.hpp"

namespace synbench::emulator {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct RowBuilder {
  std::vector<ParamRow>& rows;
  // Positive quantity from the thesis.
  void pos(std::string key, double* f, std::string source, std::string doc, bool assumed = false) {
    rows.push_back({std::move(key), f, 0, kInf, true, assumed, std::move(source), std::move(doc)});
  }
  void num(std::string key, double* f, double lo, double hi, std::string source, std::string doc,
           bool assumed = false) {
    rows.push_back({std::move(key), f, lo, hi, false, assumed, std::move(source), std::move(doc)});
  }
  void integer(std::string key, int* f, int lo, int hi, std::string source, std::string doc,
               bool assumed = false) {
    rows.push_back({std::move(key), f, double(lo), double(hi), false, assumed, std::move(source),
                    std::move(doc)});
  }
  void flag(std::string key, bool* f, std::string source, std::string doc, bool assumed = false) {
    rows.push_back({std::move(key), f, 0, 0, false, assumed, std::move(source), std::move(doc)});
  }
  template <typename E, std::size_t N>
  void choice(std::string key, E* f, const std::array<std::string_view, N>& names, std::string source,
              std::string doc, bool assumed = false) {
    ChoiceField c{names, [f] { return static_cast<std::size_t>(*f); }, [f](std::size_t i) { *f = static_cast<E>(i); }};
    rows.push_back({std::move(key), std::move(c), 0, 0, false, assumed, std::move(source), std::move(doc)});
  }
};

constexpr bool A = true;  // marks an [assumed] value

void flux_rows(RowBuilder& b, const std::string& axis, FluxAxisParams& p) {
  const std::string k = "synrm.flux_" + axis + ".";
  b.pos(k + "l0_H", &p.l0_H, "Table 1.2", "unsaturated inductance L" + axis + "0");
  b.pos(k + "psi0_Wb", &p.psi0_Wb, "Table 1.2", "saturated branch offset Psi" + axis + "0");
  b.pos(k + "l1_H", &p.l1_H, "Table 1.2", "saturated branch slope L" + axis + "1");
  b.num(k + "beta_WbA", &p.beta_WbA, -kInf, 0, "Table 1.2",
        "saturated branch hyperbolic term beta_" + axis + " (negative)");
}

}  // namespace

ConfigError::ConfigError(drivers::JsonError error)
    : std::runtime_error(error.pointer.empty() ? error.reason : drivers::to_string(error)), error_(std::move(error)) {}

std::vector<ParamRow> param_table(TwinConfig& c) {
  std::vector<ParamRow> rows;
  RowBuilder b{rows};
  auto& m = c.synrm;
  b.integer("synrm.pole_pairs", &m.pole_pairs, 1, 32, "Table 1.1", "pole pairs Pp");
  b.pos("synrm.rs_ohm", &m.rs_ohm, "Table 1.1", "stator resistance at rs_ref_temp_C");
  b.num("synrm.rs_ref_temp_C", &m.rs_ref_temp_C, -50, 200, "physics.md 1", "temperature at which rs_ohm holds");
  b.num("synrm.rs_temp_coeff_per_K", &m.rs_temp_coeff_per_K, 0, 0.01, "copper", "Rs(T) = rs (1 + a (T - Tref))");
  b.pos("synrm.inertia_kgm2", &m.inertia_kgm2, "Table 1.1", "SynRM rotor inertia J");
  b.num("synrm.b1_Nms_per_rad", &m.b1_Nms_per_rad, 0, 1, "Table 1.1", "viscous friction B1 (coupled bench)");
  b.num("synrm.b2_Nms2_per_rad2", &m.b2_Nms2_per_rad2, 0, 1, "assumed", "fan loss B2", A);
  flux_rows(b, "d", m.flux_d);
  flux_rows(b, "q", m.flux_q);
  b.num("synrm.core_kh_Ws_per_radWb2", &m.core_kh_Ws_per_radWb2, 0, 10, "assumed",
        "hysteresis term of P_Fe = (kh w_e + ke w_e^2) |Psi|^2", A);
  b.num("synrm.core_ke_Ws2_per_rad2Wb2", &m.core_ke_Ws2_per_rad2Wb2, 0, 1, "assumed",
        "eddy-current term of P_Fe", A);

  auto& t = c.thermal;
  b.pos("thermal.capacity_J_per_K", &t.capacity_J_per_K, "assumed", "thermal capacity C_th", A);
  b.pos("thermal.resistance_K_per_W", &t.resistance_K_per_W, "assumed", "thermal resistance to ambient R_th", A);
  b.num("thermal.ambient_C", &t.ambient_C, -40, 80, "assumed", "ambient temperature", A);
  b.num("thermal.initial_C", &t.initial_C, -40, 150, "Sec. 6.3.2", "winding temperature at start (bench setpoint)");

  auto& l = c.load;
  b.integer("load.pole_pairs", &l.pole_pairs, 1, 32, "assumed", "PMSM pole pairs", A);
  b.pos("load.psi_pm_Wb", &l.psi_pm_Wb, "assumed", "PMSM magnet flux", A);
  b.pos("load.rs_ohm", &l.rs_ohm, "assumed", "PMSM stator resistance", A);
  b.pos("load.ls_H", &l.ls_H, "assumed", "PMSM synchronous inductance", A);
  b.pos("load.inertia_kgm2", &l.inertia_kgm2, "eq. 6.8", "PMSM inertia (J_tot = 3.64e-3 with the SynRM)");
  b.num("load.b1_Nms_per_rad", &l.b1_Nms_per_rad, 0, 1, "assumed", "PMSM viscous friction B1G", A);
  b.pos("load.current_bandwidth_Hz", &l.current_bandwidth_Hz, "assumed", "load drive current loop bandwidth", A);
  b.pos("load.current_limit_A", &l.current_limit_A, "assumed", "load drive current limit", A);
  b.pos("load.torque_ramp_Nm_per_s", &l.torque_ramp_Nm_per_s, "assumed", "load torque setpoint ramp", A);

  b.integer("encoder.resolution_bits", &c.encoder.resolution_bits, 8, 24, "Sec. 6.1", "encoder resolution");

  auto& pl = c.plant;
  b.num("plant.flux_d_scale", &pl.flux_d_scale, 0.2, 5, "study", "plant's d-axis flux map / the model's (firmware keeps synrm)");
  b.num("plant.flux_q_scale", &pl.flux_q_scale, 0.2, 5, "study", "plant's q-axis flux map / the model's");
  b.num("plant.rs_scale", &pl.rs_scale, 0.2, 5, "study", "plant's stator resistance / synrm.rs_ohm");
  b.num("plant.inertia_scale", &pl.inertia_scale, 0.2, 5, "study", "plant's SynRM rotor inertia / synrm.inertia_kgm2");
  b.num("plant.encoder_offset_deg", &pl.encoder_offset_deg, -180, 180, "study", "encoder mounting offset (electrical)");

  auto& i = c.inverter;
  b.num("inverter.pwm_frequency_Hz", &i.pwm_frequency_Hz, 1000, 50000, "Sec. 6.1", "PWM frequency = simulation step rate");
  b.num("inverter.dead_time_s", &i.dead_time_s, 0, 10e-6, "assumed", "dead time", A);
  b.flag("inverter.dead_time_compensation", &i.dead_time_compensation, "Sec. 6.1", "dead-time compensation LUT on");
  b.pos("inverter.dead_time_current_band_A", &i.dead_time_current_band_A, "assumed",
        "current below which the dead-time error fades linearly to zero", A);
  b.num("inverter.vce0_V", &i.vce0_V, 0, 5, "assumed", "IGBT on-state threshold voltage", A);
  b.num("inverter.rce_ohm", &i.rce_ohm, 0, 5, "assumed", "IGBT on-state slope resistance", A);
  b.num("inverter.vf0_V", &i.vf0_V, 0, 5, "assumed", "diode forward threshold voltage", A);
  b.num("inverter.rf_ohm", &i.rf_ohm, 0, 5, "assumed", "diode slope resistance", A);
  b.num("inverter.esw0_J", &i.esw0_J, 0, 1e-2, "assumed", "switching energy per on+off pair at zero current", A);
  b.num("inverter.esw_per_A_J", &i.esw_per_A_J, 0, 1e-2, "assumed", "switching energy per ampere", A);
  b.pos("inverter.esw_ref_V", &i.esw_ref_V, "assumed", "DC voltage at which the switching energies hold", A);

  auto& d = c.dc_bus;
  b.pos("dc_bus.source_V", &d.source_V, "assumed", "open-circuit voltage of the rectified supply", A);
  b.pos("dc_bus.source_ohm", &d.source_ohm, "assumed", "source resistance", A);
  b.pos("dc_bus.capacitance_F", &d.capacitance_F, "assumed", "bus capacitance", A);
  b.pos("dc_bus.brake_on_V", &d.brake_on_V, "assumed", "brake chopper switches on above", A);
  b.pos("dc_bus.brake_off_V", &d.brake_off_V, "assumed", "brake chopper switches off below", A);
  b.pos("dc_bus.brake_ohm", &d.brake_ohm, "assumed", "braking resistor", A);

  auto& v = c.vfc;
  b.pos("vfc.f0_Hz", &v.f0_Hz, "assumed", "VFC frequency at zero current", A);
  b.pos("vfc.kf_Hz_per_A", &v.kf_Hz_per_A, "assumed", "VFC gain", A);
  b.num("vfc.motor.gain_error", &v.motor.gain_error, -0.5, 0.5, "assumed", "true/nominal gain - 1, I_dcM channel", A);
  b.num("vfc.motor.offset_error_A", &v.motor.offset_error_A, -1, 1, "assumed", "input offset, I_dcM channel", A);
  b.num("vfc.generator.gain_error", &v.generator.gain_error, -0.5, 0.5, "assumed", "true/nominal gain - 1, I_dcG channel", A);
  b.num("vfc.generator.offset_error_A", &v.generator.offset_error_A, -1, 1, "assumed", "input offset, I_dcG channel", A);

  auto& q = c.mcidc;
  b.num("mcidc.noise_sigma_per_H", &q.noise_sigma_per_H, 0, 10, "eq. 6.4", "white noise of one R'_ph sample");
  b.num("mcidc.gain_error", &q.gain_error, -0.5, 0.5, "assumed", "relative gain error delta_R", A);
  b.num("mcidc.deformation_amplitude_per_H", &q.deformation_amplitude_per_H, 0, 10, "assumed",
        "amplitude of the periodic deformation A_R (Figs. 6.6 to 6.8)", A);
  b.integer("mcidc.deformation_harmonic", &q.deformation_harmonic, 0, 24, "assumed",
            "harmonic order of A_R in (th_e + th_phN)", A);
  b.num("mcidc.min_active_time_s", &q.min_active_time_s, 0, 50e-6, "assumed",
        "shortest active vector whose current slope can be measured (CAPWM)", A);

  auto& f = c.firmware;
  b.pos("firmware.current_bandwidth_Hz", &f.current_bandwidth_Hz, "Sec. 6.1", "current loop bandwidth");
  b.pos("firmware.speed_bandwidth_Hz", &f.speed_bandwidth_Hz, "Sec. 6.1", "speed loop bandwidth");
  b.num("firmware.speed_loop_rate_Hz", &f.speed_loop_rate_Hz, 10, 10000, "Sec. 6.1", "speed loop rate");
  b.pos("firmware.speed_observer_bandwidth_Hz", &f.speed_observer_bandwidth_Hz, "assumed",
        "encoder speed tracking observer bandwidth", A);
  b.num("firmware.current_noise_sigma_A", &f.current_noise_sigma_A, 0, 1, "eq. 6.5", "phase current noise");
  b.integer("firmware.adc_bits", &f.adc_bits, 8, 24, "Sec. 6.1", "current ADC resolution");
  b.pos("firmware.adc_range_A", &f.adc_range_A, "Sec. 6.1", "current ADC full scale (+/-)");
  b.pos("firmware.current_limit_A", &f.current_limit_A, "assumed", "speed controller output limit (peak)", A);
  b.pos("firmware.speed_ramp_rpm_per_s", &f.speed_ramp_rpm_per_s, "assumed", "speed setpoint ramp", A);
  b.pos("firmware.sensorless_angle_slew_deg_per_s", &f.sensorless_angle_slew_deg_per_s, "assumed",
        "current-angle rate limit while an estimator is the position source", A);
  b.num("firmware.lock_guard_deg", &f.lock_guard_deg, 0, 90, "assumed",
        "lock guard: estimated minus encoder angle beyond which the encoder takes over until the next point (0: off)", A);
  b.num("firmware.lock_guard_speed_rpm", &f.lock_guard_speed_rpm, 0, 10000, "assumed",
        "lock guard: or estimated minus encoder speed beyond this (before the estimator has held: for 0.2 s) (0: off)", A);
  b.num("firmware.lock_guard_s", &f.lock_guard_s, 0, 1, "assumed", "lock guard: how long the angle or speed must stay beyond it", A);
  b.num("firmware.lock_guard_current_A", &f.lock_guard_current_A, 0, 100, "assumed",
        "lock guard: or a current vector above this, sensorless (0: off)", A);
  b.pos("firmware.telemetry_filter_s", &f.telemetry_filter_s, "assumed", "time constant of telemetry low-pass filters", A);
  b.integer("firmware.window_batches", &f.window_batches, 2, 64, "assumed",
            "equal sub-windows (batches) a window's means and the meter's counts are also kept over (type A uncertainty)", A);
  b.pos("firmware.max_speed_rpm", &f.max_speed_rpm, "Table 1.1", "largest speed setpoint accepted");
  b.pos("firmware.overspeed_trip_rpm", &f.overspeed_trip_rpm, "assumed", "over-speed trip", A);
  b.pos("firmware.overcurrent_trip_A", &f.overcurrent_trip_A, "assumed", "over-current trip (peak phase)", A);
  b.pos("firmware.overvoltage_trip_V", &f.overvoltage_trip_V, "Sec. 6.1", "over-voltage trip (capacitor limit)");
  b.pos("firmware.undervoltage_trip_V", &f.undervoltage_trip_V, "assumed", "under-voltage trip", A);
  b.pos("firmware.overtemp_trip_C", &f.overtemp_trip_C, "assumed", "winding over-temperature trip", A);
  b.choice("firmware.pwm", &f.pwm, drivers::kPwmNames, "Sec. 5.2", "switching scheme at start");
  b.choice("firmware.disable_action", &f.disable_action, kDisableActionNames, "assumed",
           "the master's disable: gates off at once (a safe torque off), or ramp: the speed ramped to zero at "
           "speed_ramp_rpm_per_s first, reading stopping (an SS1-style drive)", A);

  auto& h = c.estimators.hfi;
  b.pos("estimators.hfi.voltage_V", &h.voltage_V, "Sec. 6.2.2", "HFI carrier amplitude on the estimated d axis");
  b.pos("estimators.hfi.frequency_Hz", &h.frequency_Hz, "Sec. 6.2.2", "HFI carrier frequency");
  b.pos("estimators.hfi.bandpass_bandwidth_Hz", &h.bandpass_bandwidth_Hz, "assumed",
        "HFI band-pass bandwidth (thesis Sec. 6.2.2: 25 Hz, whose 13 ms envelope lag destabilised the PLL)", A);
  b.pos("estimators.hfi.pll_bandwidth_Hz", &h.pll_bandwidth_Hz, "assumed", "HFI phase-locked loop bandwidth", A);
  b.num("estimators.hfi.align_s", &h.align_s, 0, 10, "assumed",
        "HFI initial position detection after each start: the carrier runs this long before the speed loop applies current", A);
  auto& e = c.estimators.eemf;
  b.pos("estimators.eemf.ld_H", &e.ld_H, "Sec. 6.2.3", "EEMF-CONST d inductance");
  b.pos("estimators.eemf.lq_H", &e.lq_H, "Sec. 6.2.3", "EEMF-CONST q inductance");
  b.pos("estimators.eemf.observer_bandwidth_Hz", &e.observer_bandwidth_Hz, "Sec. 6.2.3", "EEMF tracking observer bandwidth");
  b.num("estimators.eemf.stiffness_margin", &e.stiffness_margin, 0, 100, "assumed",
        "EEMF observer bandwidth at least this times the shaft's angle-error growth rate above the MTPA angle (0: off)", A);
  b.num("estimators.eemf.speed_filter_s", &e.speed_filter_s, 0, 1, "assumed",
        "low-pass time constant on the EEMF observer's reported speed (its proportional path's noise)", A);
  b.num("estimators.eemf.min_speed_rpm", &e.min_speed_rpm, 0, 10000, "Sec. 6.3.2", "below it EEMF hands over to the low-speed source");
  b.num("estimators.eemf.handover_hysteresis_rpm", &e.handover_hysteresis_rpm, 0, 1000, "assumed",
        "hysteresis around the minimum speed", A);
  b.choice("estimators.eemf.low_speed_source", &e.low_speed_source, kLowSpeedSourceNames, "Sec. 6.3.2",
           "position source below the minimum speed");
  b.pos("estimators.eemf.lut_ld_scale", &e.lut_ld_scale, "Sec. 4 (4.1)", "EEMF-LUT table deformation kd (1 = exact tables)");
  b.pos("estimators.eemf.lut_lq_scale", &e.lut_lq_scale, "Sec. 4 (4.2)", "EEMF-LUT table deformation kq (1 = exact tables)");
  b.choice("estimators.eemf.lut_rotation_speed", &e.lut_rotation_speed, kLutRotationSpeedNames, "Sec. 6.2.3",
           "EEMF-LUT: rotor speed in the w Lq terms and the derivative's frame, the tracking observer's (the thesis; EEMF-CONST and EEMF-RLS always) or the active flux's (ours, docs/estimators.md)");
  b.choice("estimators.eemf.error_signal", &e.error_signal, kEemfErrorSignalNames, "Sec. 6.2.3",
           "EEMF-LUT and EEMF-RLS: the angle error from the EEMF's direction only (the thesis) or from its whole vector, the magnitude against the model's prediction as well (ours, docs/estimators.md; EEMF-CONST always the direction)");
  b.num("estimators.eemf.rls_emf_scale_filter_s", &e.rls_emf_scale_filter_s, 0, 100, "assumed",
        "EEMF-RLS with the vector error: time constant over which the predicted EEMF magnitude is scaled to the measured one (the identified inductances miss the saturated d axis' flux offset; 0: not scaled)", A);
  b.flag("estimators.eemf.rls_flux_offset", &e.rls_flux_offset, "assumed",
         "EEMF-RLS: the static flux of the rotation terms and of the magnitude prediction from the identified inductances plus the flux offsets of the RLS's affine part (ours, docs/estimators.md; false: the incremental inductances alone)", A);
  b.num("estimators.eemf.flux_blend_rad_s", &e.flux_blend_rad_s, 0, 1000, "assumed",
        "active-flux speed: below this the voltage model's flux is pulled to the model's at the estimated angle", A);
  b.num("estimators.eemf.flux_speed_filter_s", &e.flux_speed_filter_s, 0, 1, "assumed",
        "active-flux speed: low-pass time constant on the active flux angle's rate", A);
  b.num("estimators.eemf.rls_forgetting", &e.rls_forgetting, 0.5, 1.0, "Sec. 6.2.3", "RLS forgetting factor");
  b.pos("estimators.eemf.rls_p0", &e.rls_p0, "Sec. 6.2.3", "RLS initial covariance diagonal");
  b.num("estimators.eemf.rls_sample_s", &e.rls_sample_s, 1e-5, 0.1, "assumed", "RLS sample period", A);
  b.num("estimators.eemf.rls_estimate_filter_s", &e.rls_estimate_filter_s, 0, 100, "assumed",
        "low-pass time constant on the RLS estimates the drive reports", A);
  b.num("estimators.eemf.rls_model_filter_s", &e.rls_model_filter_s, 0, 100, "assumed",
        "low-pass time constant on the RLS estimates the EEMF observer uses (slower than the reported ones: identified in the estimated frame they move with the observer's angle error; docs/estimators.md)", A);
  b.num("estimators.eemf.rls_warmup_s", &e.rls_warmup_s, 0, 100, "assumed",
        "identification time before the observer takes the RLS estimates (the constants until then)", A);
  b.num("estimators.eemf.prbs_voltage_V", &e.prbs_voltage_V, 0, 100, "Sec. 6.2.3", "PRBS amplitude on both axes");
  b.pos("estimators.eemf.prbs_bit_s", &e.prbs_bit_s, "Sec. 6.2.3", "PRBS bit period");
  b.num("estimators.ekf.rs_speed_threshold_rpm", &c.estimators.ekf.rs_speed_threshold_rpm, 0, 10000, "assumed",
        "EKF-RS holds Rs (no process noise) below this speed (Fig. 5.21)", A);

  rows.push_back({"sim.seed", &c.sim.seed_int, 0, 2147483647.0, false, false, "-", "noise generator seed"});
  return rows;
}

namespace {

std::string describe_range(const ParamRow& r) {
  std::ostringstream s;
  s << (r.min_exclusive ? "(" : "[") << r.min << ", " << r.max << "]";
  return s.str();
}

// "synrm.flux_d.l0_H" -> "/synrm/flux_d/l0_H" (keys hold neither '~' nor '/').
std::string pointer_of(std::string key) {
  for (auto& ch : key)
    if (ch == '.') ch = '/';
  return "/" + key;
}

[[noreturn]] void fail(const std::string& key, std::string reason) {
  throw ConfigError({pointer_of(key), std::move(reason)});
}

// The first problem the reader found, thrown: the twin config stops at its first bad key.
void throw_first(const drivers::JsonReader& r) {
  if (!r.ok()) throw ConfigError(r.errors.front());
}

void set_row(const ParamRow& r, const drivers::JsonNode& v) {
  std::visit(
      [&](auto& f) {
        using F = std::remove_cvref_t<decltype(f)>;
        if constexpr (std::is_same_v<F, bool*>) {
          if (auto b = v.boolean()) *f = *b;
        } else if constexpr (std::is_same_v<F, ChoiceField>) {
          const auto dot = r.key.rfind('.');
          if (auto i = v.choice<std::size_t>(f.names, r.key.substr(dot + 1))) f.set(*i);
        } else if constexpr (std::is_same_v<F, int*>) {
          if (auto i = v.integer(static_cast<std::int64_t>(r.min), static_cast<std::int64_t>(r.max)))
            *f = static_cast<int>(*i);
        } else {
          const auto value = v.number([&](double x) {
            const bool low = r.min_exclusive ? x <= r.min : x < r.min;
            return low || x > r.max ? drivers::format_number(x) + " is outside " + describe_range(r) : std::string();
          });
          if (value) *f = *value;
        }
      },
      r.field);
  throw_first(v.reader());
}

void walk(const drivers::JsonNode& node, const std::string& prefix,
          const std::map<std::string, const ParamRow*>& rows) {
  for (const auto& [name, value] : node.members()) {
    const std::string key = prefix.empty() ? name : prefix + "." + name;
    if (auto row = rows.find(key); row != rows.end()) {
      set_row(*row->second, value);
    } else if (value.json().is_object()) {
      bool section = false;
      for (const auto& [k, r] : rows) section = section || k.rfind(key + ".", 0) == 0;
      if (!section) value.fail("unknown field");
      throw_first(node.reader());
      walk(value, key, rows);
    } else {
      value.fail("unknown field");
      throw_first(node.reader());
    }
  }
}

synbench::Json row_value(const ParamRow& r) {
  return std::visit(
      [](const auto& f) {
        if constexpr (std::is_same_v<std::remove_cvref_t<decltype(f)>, ChoiceField>)
          return synbench::Json(f.names[f.get()]);
        else
          return synbench::Json(*f);
      },
      r.field);
}

}  // namespace

void apply_json(TwinConfig& config, const synbench::Json& doc) {
  drivers::JsonReader reader;
  const drivers::JsonNode root = drivers::read_root(doc, reader);
  root.object("the document must be a JSON object");
  throw_first(reader);
  auto table = param_table(config);
  std::map<std::string, const ParamRow*> rows;
  for (const auto& r : table) rows[r.key] = &r;
  walk(root, "", rows);
  validate(config);
}

TwinConfig load_twin_config_file(const std::string& path) {
  const drivers::JsonParsed read = drivers::read_json_file(path);
  if (!read.ok()) throw ConfigError({"", read.error});
  TwinConfig config;
  apply_json(config, read.doc);
  return config;
}

void validate(const TwinConfig& c) {
  if (c.dc_bus.brake_off_V >= c.dc_bus.brake_on_V)
    fail("dc_bus.brake_off_V", "must be below dc_bus.brake_on_V");
  if (c.dc_bus.brake_on_V >= c.firmware.overvoltage_trip_V)
    fail("dc_bus.brake_on_V", "must be below firmware.overvoltage_trip_V");
  if (c.firmware.undervoltage_trip_V >= c.dc_bus.source_V)
    fail("firmware.undervoltage_trip_V", "must be below dc_bus.source_V");
  if (c.firmware.max_speed_rpm >= c.firmware.overspeed_trip_rpm)
    fail("firmware.max_speed_rpm", "must be below firmware.overspeed_trip_rpm");
  if (c.firmware.current_limit_A >= c.firmware.overcurrent_trip_A)
    fail("firmware.current_limit_A", "must be below firmware.overcurrent_trip_A");
  if (c.firmware.overcurrent_trip_A >= c.firmware.adc_range_A)
    fail("firmware.overcurrent_trip_A", "must be below firmware.adc_range_A");
  if (c.firmware.speed_loop_rate_Hz > c.inverter.pwm_frequency_Hz)
    fail("firmware.speed_loop_rate_Hz", "must not exceed inverter.pwm_frequency_Hz");
  const double ratio = c.inverter.pwm_frequency_Hz / c.firmware.speed_loop_rate_Hz;
  if (std::abs(ratio - std::round(ratio)) > 1e-9)
    fail("firmware.speed_loop_rate_Hz", "must divide inverter.pwm_frequency_Hz");
  if (c.estimators.hfi.frequency_Hz * 4 > c.inverter.pwm_frequency_Hz)
    fail("estimators.hfi.frequency_Hz", "must be at most a quarter of the PWM frequency");
  if (c.estimators.eemf.rls_sample_s < c.step_s())
    fail("estimators.eemf.rls_sample_s", "must be at least one PWM period");
  if (c.firmware.current_bandwidth_Hz * 10 > c.inverter.pwm_frequency_Hz)
    fail("firmware.current_bandwidth_Hz", "must be at most a tenth of the PWM frequency");
  auto check_axis = [](const FluxAxisParams& p, const std::string& axis) {
    // The two branches must cross (the switch point is their upper crossing).
    const double a = p.l0_H - p.l1_H;
    if (a <= 0) fail("synrm.flux_" + axis + ".l1_H", "must be below l0_H");
    if (p.psi0_Wb * p.psi0_Wb + 4 * a * p.beta_WbA < 0)
      fail("synrm.flux_" + axis + ".beta_WbA", "the saturated branch never meets the linear one");
  };
  check_axis(c.synrm.flux_d, "d");
  check_axis(c.synrm.flux_q, "q");
}

synbench::Json to_json(const TwinConfig& config) {
  TwinConfig copy = config;
  const auto pointer = [](std::string key) {
    for (auto& ch : key) if (ch == '.') ch = '/';
    return synbench::Json::json_pointer("/" + key);
  };
  // Keys in the table's order, each section's _assumed after its values.
  synbench::Json out = {{"_comment", "synbench twin config. Defaults: thesis values; keys listed in a section's _assumed "
                                     "are our calibration, not from the thesis. See docs/emulator-config.md."}};
  const auto rows = param_table(copy);
  for (const auto& r : rows) out[pointer(r.key)] = row_value(r);
  for (const auto& r : rows) {
    if (!r.assumed) continue;
    const auto dot = r.key.rfind('.');
    out[pointer(r.key.substr(0, dot) + "._assumed")].push_back(r.key.substr(dot + 1));
  }
  return out;
}

std::string markdown_reference(const TwinConfig& config) {
  TwinConfig copy = config;
  std::ostringstream s;
  s << "| key | default | valid | source | meaning |\n|---|---|---|---|---|\n";
  for (const auto& r : param_table(copy)) {
    std::string valid;
    if (std::holds_alternative<bool*>(r.field)) {
      valid = "true, false";
    } else if (const auto* c = std::get_if<ChoiceField>(&r.field)) {
      for (const auto n : c->names) valid += (valid.empty() ? "" : ", ") + std::string(n);
    } else {
      valid = describe_range(r);
    }
    s << "| `" << r.key << "` | " << row_value(r).dump() << " | " << valid << " | "
      << (r.assumed ? "**[assumed]**" : r.source) << " | " << r.doc << " |\n";
  }
  return s.str();
}

}  // namespace synbench::emulator

namespace synbench::emulator {

SynrmParams TwinConfig::plant_synrm() const {
  SynrmParams p = synrm;
  // Every term of a flux branch scales, so Psi(i) scales at every current and the knee stays put.
  for (auto [axis, k] : {std::pair{&p.flux_d, plant.flux_d_scale}, std::pair{&p.flux_q, plant.flux_q_scale}}) {
    axis->l0_H *= k;
    axis->psi0_Wb *= k;
    axis->l1_H *= k;
    axis->beta_WbA *= k;
  }
  p.rs_ohm *= plant.rs_scale;
  p.inertia_kgm2 *= plant.inertia_scale;
  return p;
}

void TwinConfig::scale_bus_to(double udc_V) {
  const double k = udc_V / dc_bus.source_V;
  dc_bus.source_V = udc_V;
  dc_bus.brake_on_V *= k;
  dc_bus.brake_off_V *= k;
  firmware.overvoltage_trip_V *= k;
  firmware.undervoltage_trip_V *= k;
}

}  // namespace synbench::emulator
