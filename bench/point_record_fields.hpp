// The member tables of the point record and of the twin's truth window: each field's name
// (experiment.md Sec. 2.5, its unit in the name) and its member, in the record's one order. Every
// form of a record is a loop over these tables: to_json and to_text, the database's columns and
// their binding, CSV and the JSON export. A new field is one line here, plus its migration
// (db/migrations.cpp: a step's SQL is history) and its line in docs/record.md; the static_asserts
// below and tests/bench, tests/db compare the table with the struct, the schema and the docs.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>

#include "bench/point_record.hpp"

namespace synbench::bench {

// One field: its name and its member of S.
template <class S, class T>
struct Field {
  using value_type = T;
  std::string_view name;
  T S::*member;
};
template <class S, class T>
Field(std::string_view, T S::*) -> Field<S, T>;

using drivers::TruthWindow;

inline constexpr std::tuple kTruthFields{
    Field{"pin_W", &TruthWindow::pin_W},     Field{"pcu_W", &TruthWindow::pcu_W},
    Field{"pfe_W", &TruthWindow::pfe_W},     Field{"pmech_W", &TruthWindow::pmech_W},
    Field{"pinvm_W", &TruthWindow::pinvm_W}, Field{"pm_W", &TruthWindow::pm_W},
    Field{"temp_C", &TruthWindow::temp_C},
};

// The record's order (its JSON keys, the CSV header, docs/record.md), not the struct's
// declaration order: fields added later come last, where the migrations appended their columns.
inline constexpr std::tuple kPointRecordFields{
    Field{"speed_rpm", &PointRecord::speed_rpm},
    Field{"load_Nm", &PointRecord::load_Nm},
    Field{"angle_deg", &PointRecord::angle_deg},
    Field{"estimator", &PointRecord::estimator},
    Field{"pwm", &PointRecord::pwm},
    Field{"speed_meas_rpm", &PointRecord::speed_meas_rpm},
    Field{"im_A", &PointRecord::im_A},
    Field{"id_A", &PointRecord::id_A},
    Field{"iq_A", &PointRecord::iq_A},
    Field{"ud_V", &PointRecord::ud_V},
    Field{"uq_V", &PointRecord::uq_V},
    Field{"udc_V", &PointRecord::udc_V},
    Field{"idcm_A", &PointRecord::idcm_A},
    Field{"idcg_A", &PointRecord::idcg_A},
    Field{"pdcm_W", &PointRecord::pdcm_W},
    Field{"pdcg_W", &PointRecord::pdcg_W},
    Field{"pm_W", &PointRecord::pm_W},
    Field{"efficiency", &PointRecord::efficiency},
    Field{"pos_err_min_deg", &PointRecord::pos_err_min_deg},
    Field{"pos_err_mean_deg", &PointRecord::pos_err_mean_deg},
    Field{"pos_err_max_deg", &PointRecord::pos_err_max_deg},
    Field{"speed_err_rpm", &PointRecord::speed_err_rpm},
    Field{"ld_est_H", &PointRecord::ld_est_H},
    Field{"lq_est_H", &PointRecord::lq_est_H},
    Field{"rs_est_ohm", &PointRecord::rs_est_ohm},
    Field{"ld_err_pct", &PointRecord::ld_err_pct},
    Field{"lq_err_pct", &PointRecord::lq_err_pct},
    Field{"rs_err_pct", &PointRecord::rs_err_pct},
    Field{"temp_C", &PointRecord::temp_C},
    Field{"window_s", &PointRecord::window_s},
    Field{"samples", &PointRecord::samples},
    Field{"settle_s", &PointRecord::settle_s},
    Field{"voltage_limited", &PointRecord::voltage_limited},
    Field{"unstable", &PointRecord::unstable},
    Field{"fault", &PointRecord::fault},
    Field{"below_min_speed", &PointRecord::below_min_speed},  // schema version 2
    Field{"fallback_fraction", &PointRecord::fallback_fraction},
    Field{"lock_lost", &PointRecord::lock_lost},            // schema version 3
    Field{"window_source", &PointRecord::window_source},    // schema version 5
    Field{"fault_code_raw", &PointRecord::fault_code_raw},  // schema version 6
    Field{"angle_meas_deg", &PointRecord::angle_meas_deg},  // schema version 7
    Field{"angle_off", &PointRecord::angle_off},
    Field{"im_u_A", &PointRecord::im_u_A},  // schema version 8
    Field{"pdcm_u_W", &PointRecord::pdcm_u_W},
    Field{"pdcg_u_W", &PointRecord::pdcg_u_W},
    Field{"pm_u_W", &PointRecord::pm_u_W},
    Field{"efficiency_u", &PointRecord::efficiency_u},
    Field{"im_u_repeat_A", &PointRecord::im_u_repeat_A},
    Field{"pdcm_u_repeat_W", &PointRecord::pdcm_u_repeat_W},
    Field{"efficiency_u_repeat", &PointRecord::efficiency_u_repeat},
    Field{"truth", &PointRecord::truth},  // a nested table (kTruthFields); its own column
};

// The table of a struct with one: a field of that type (or an optional one) is an object in
// JSON, flattened as <field>_<name> in CSV and JSON text in its database column.
template <class S>
struct FieldTable;
template <>
struct FieldTable<PointRecord> {
  static constexpr const auto& fields = kPointRecordFields;
};
template <>
struct FieldTable<TruthWindow> {
  static constexpr const auto& fields = kTruthFields;
};
template <class T>
concept HasFieldTable = requires { FieldTable<T>::fields; };

// Calls f(field) for each field of a table, in order.
template <class Fields, class F>
constexpr void for_each_field(const Fields& fields, F&& f) {
  std::apply([&](const auto&... field) { (f(field), ...); }, fields);
}

template <class Fields>
constexpr auto field_names(const Fields& fields) {
  return std::apply([](const auto&... field) { return std::array<std::string_view, sizeof...(field)>{field.name...}; },
                    fields);
}

// optional<T> -> T, else T: what a field holds when it holds something.
template <class T>
struct HeldType {
  using type = T;
};
template <class T>
struct HeldType<std::optional<T>> {
  using type = T;
};
template <class T>
using held_t = typename HeldType<T>::type;

// The enum fields' text, as every form of the record writes it, and back (nullopt: not a name).
constexpr std::string_view field_text(drivers::Estimator e) { return drivers::name(e); }
constexpr std::string_view field_text(drivers::Pwm p) { return drivers::name(p); }
constexpr std::string_view field_text(drivers::WindowKeeper k) { return drivers::keeper_name(k); }
inline std::optional<drivers::Estimator> parse_field_text(std::string_view s, drivers::Estimator*) {
  return drivers::parse_estimator(s);
}
inline std::optional<drivers::Pwm> parse_field_text(std::string_view s, drivers::Pwm*) { return drivers::parse_pwm(s); }
inline std::optional<drivers::WindowKeeper> parse_field_text(std::string_view s, drivers::WindowKeeper*) {
  for (const auto k : {drivers::WindowKeeper::device, drivers::WindowKeeper::host})
    if (s == field_text(k)) return k;
  return std::nullopt;
}
template <class T>
concept TextField = requires(T v) { field_text(v); };

namespace detail {

// Converts to any type: T{AnyMember{} x N} compiles for N up to T's number of members.
struct AnyMember {
  template <class T>
  operator T() const;
};
template <class T, std::size_t... I>
constexpr bool initializable_with(std::index_sequence<I...>) {
  return requires { T{(void(I), AnyMember{})...}; };
}
template <class T, std::size_t N = 0>
constexpr std::size_t member_count() {
  if constexpr (initializable_with<T>(std::make_index_sequence<N + 1>{})) return member_count<T, N + 1>();
  else return N;
}

template <std::size_t N>
constexpr bool unique(const std::array<std::string_view, N>& names) {
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t j = i + 1; j < N; ++j)
      if (names[i] == names[j]) return false;
  return true;
}

}  // namespace detail

// A member added to a struct but not to its table fails to compile here (tests/bench checks that
// the table names each member once).
static_assert(detail::member_count<PointRecord>() == std::tuple_size_v<decltype(kPointRecordFields)>,
              "PointRecord has a member kPointRecordFields does not list (or the reverse)");
static_assert(detail::member_count<TruthWindow>() == std::tuple_size_v<decltype(kTruthFields)>,
              "TruthWindow has a member kTruthFields does not list (or the reverse)");
static_assert(detail::unique(field_names(kPointRecordFields)) && detail::unique(field_names(kTruthFields)));

}  // namespace synbench::bench
