// One measured operating point, with the field names of experiment.md Sec. 2.5: the one schema
// used by the JSON output, the database, CSV export and the REST API. A member added here goes
// into its table too (bench/point_record_fields.hpp; a static_assert there insists).
#pragma once

#include "drivers/json_fwd.hpp"

#include <cstdint>
#include <optional>
#include <string>

#include "drivers/devices.hpp"
#include "drivers/modes.hpp"

namespace synbench::bench {

struct PointRecord {
  // setpoints
  double speed_rpm = 0, load_Nm = 0, angle_deg = 0;
  drivers::Estimator estimator = drivers::Estimator::encoder;
  drivers::Pwm pwm = drivers::Pwm::capwm;
  // measured
  double speed_meas_rpm = 0, im_A = 0, id_A = 0, iq_A = 0, ud_V = 0, uq_V = 0, udc_V = 0;
  double idcm_A = 0, idcg_A = 0, pdcm_W = 0, pdcg_W = 0, pm_W = 0, efficiency = 0;
  // estimator (empty where they do not apply)
  std::optional<double> pos_err_min_deg, pos_err_mean_deg, pos_err_max_deg, speed_err_rpm;
  std::optional<double> ld_est_H, lq_est_H, rs_est_ohm, ld_err_pct, lq_err_pct, rs_err_pct;
  // conditions
  std::optional<double> temp_C;  // empty when the SynRM drive reports no temperature
  double window_s = 0, settle_s = 0;
  // The SynRM drive's window's samples: its control periods (window_source device), or the
  // telemetry polls the bench averaged (host).
  std::uint32_t samples = 0;
  drivers::WindowKeeper window_source = drivers::WindowKeeper::device;
  // flags
  bool voltage_limited = false, unstable = false;
  std::optional<std::string> fault;
  // Below the selected estimator's minimum speed the drive ran on its low-speed fallback (HFI or
  // the encoder) for most of the window: the estimator fields describe the fallback, not it.
  bool below_min_speed = false;
  double fallback_fraction = 0;  // share of the window's samples on the fallback, 0..1
  // The estimator lost the rotor during the point: the drive's lock guard ran it on the encoder
  // from then on, so its values are not the estimator's (docs/estimators.md).
  bool lock_lost = false;
  // The device's own code of a fault its profile has no label for (fault "unknown").
  std::optional<std::int64_t> fault_code_raw;
  // The current angle th_i of the window's mean (id_A, iq_A), next to the requested angle_deg
  // (bench/current_angle.hpp); empty for a zero mean current and on rows stored before it.
  std::optional<double> angle_meas_deg;
  // angle_meas_deg is further from angle_deg than the measurement allows at this current: the
  // drive did not run at the requested angle (a warning; false below the current it is judged at).
  bool angle_off = false;
  // Standard uncertainties (k = 1, GUM) of the measured values (bench/uncertainty.hpp,
  // docs/uncertainty.md): `_u` the combined one, `_u_repeat` its part that is independent from
  // point to point (type A and quantisation), which a difference between two points of one
  // bench carries. Empty where no budget could be formed and on rows stored before them.
  std::optional<double> im_u_A, im_u_repeat_A;
  std::optional<double> pdcm_u_W, pdcm_u_repeat_W, pdcg_u_W, pm_u_W;
  std::optional<double> efficiency_u, efficiency_u_repeat;
  // emulator only: the plant's own values over the window
  std::optional<drivers::TruthWindow> truth;
};

// An object with the table's fields in its order (bench/point_record_fields.hpp): numbers, enums
// by name, null for an empty optional, truth as an object of its own table.
synbench::Json to_json(const PointRecord& r);
synbench::Json to_json(const drivers::TruthWindow& t);
// The same record for people: one "name  value" line per field.
std::string to_text(const PointRecord& r);

}  // namespace synbench::bench
