// The columns of the points table that hold a PointRecord, in the record's field order, each tied
// to its member. Internal to db/: binding and reading a record walk this one list, so the SQL and
// the struct cannot drift apart silently (tests/db compares it with bench::to_json's keys and
// with the table itself).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>

#include "bench/point_record.hpp"

namespace synbench::db::detail {

using bench::PointRecord;

using Member = std::variant<double PointRecord::*, std::optional<double> PointRecord::*,
                            drivers::Estimator PointRecord::*, drivers::Pwm PointRecord::*,
                            std::uint32_t PointRecord::*, bool PointRecord::*,
                            std::optional<std::string> PointRecord::*, drivers::WindowKeeper PointRecord::*,
                            std::optional<std::int64_t> PointRecord::*>;

struct RecordColumn {
  std::string_view name;
  Member member;
};

inline const std::array<RecordColumn, 42> kRecordColumns{{
    {"speed_rpm", &PointRecord::speed_rpm},
    {"load_Nm", &PointRecord::load_Nm},
    {"angle_deg", &PointRecord::angle_deg},
    {"estimator", &PointRecord::estimator},
    {"pwm", &PointRecord::pwm},
    {"speed_meas_rpm", &PointRecord::speed_meas_rpm},
    {"im_A", &PointRecord::im_A},
    {"id_A", &PointRecord::id_A},
    {"iq_A", &PointRecord::iq_A},
    {"ud_V", &PointRecord::ud_V},
    {"uq_V", &PointRecord::uq_V},
    {"udc_V", &PointRecord::udc_V},
    {"idcm_A", &PointRecord::idcm_A},
    {"idcg_A", &PointRecord::idcg_A},
    {"pdcm_W", &PointRecord::pdcm_W},
    {"pdcg_W", &PointRecord::pdcg_W},
    {"pm_W", &PointRecord::pm_W},
    {"efficiency", &PointRecord::efficiency},
    {"pos_err_min_deg", &PointRecord::pos_err_min_deg},
    {"pos_err_mean_deg", &PointRecord::pos_err_mean_deg},
    {"pos_err_max_deg", &PointRecord::pos_err_max_deg},
    {"speed_err_rpm", &PointRecord::speed_err_rpm},
    {"ld_est_H", &PointRecord::ld_est_H},
    {"lq_est_H", &PointRecord::lq_est_H},
    {"rs_est_ohm", &PointRecord::rs_est_ohm},
    {"ld_err_pct", &PointRecord::ld_err_pct},
    {"lq_err_pct", &PointRecord::lq_err_pct},
    {"rs_err_pct", &PointRecord::rs_err_pct},
    {"temp_C", &PointRecord::temp_C},
    {"window_s", &PointRecord::window_s},
    {"samples", &PointRecord::samples},
    {"settle_s", &PointRecord::settle_s},
    {"voltage_limited", &PointRecord::voltage_limited},
    {"unstable", &PointRecord::unstable},
    {"fault", &PointRecord::fault},
    {"below_min_speed", &PointRecord::below_min_speed},    // schema version 2
    {"fallback_fraction", &PointRecord::fallback_fraction},
    {"lock_lost", &PointRecord::lock_lost},                // schema version 3
    {"window_source", &PointRecord::window_source},        // schema version 5
    {"fault_code_raw", &PointRecord::fault_code_raw},      // schema version 6
    {"angle_meas_deg", &PointRecord::angle_meas_deg},      // schema version 7
    {"angle_off", &PointRecord::angle_off},
}};

}  // namespace synbench::db::detail
