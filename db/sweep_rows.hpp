// What both backends share besides the schema: the SQL of their statements (SQLite's `?`
// placeholders, turned into PostgreSQL's `$n` by pg_sql()), a sweep read back from a row of
// kSweepColumns and an event from one of kEventColumns, and the rules of a sweep's state changes. Internal to db/.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "db/bench_identity.hpp"
#include "db/error.hpp"
#include "db/point_columns.hpp"
#include "db/types.hpp"
#include "drivers/json.hpp"

namespace synbench::db::detail {

// `sql` with SQLite's placeholders (`?`, `?N`) as PostgreSQL's (`$1`, `$2`, ..., `$N`).
std::string pg_sql(std::string_view sql);

std::string insert_point_sql();
std::string select_points_sql();
inline constexpr std::string_view kInsertSweepSql =
    "INSERT INTO sweeps (name, created_at, state, plan_json, software_version, profiles_json, "
    "bench_config_json, calibration_json, total_points, bench_name, bench_host, devices_json, key) "
    "VALUES (?, ?, 'created', ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)";
inline constexpr std::string_view kSweepColumns =
    "SELECT s.id, s.name, s.created_at, s.started_at, s.finished_at, s.state, s.plan_json, "
    "s.software_version, s.profiles_json, s.bench_config_json, s.calibration_json, "
    "s.total_points, s.last_error, (SELECT count(*) FROM points p WHERE p.sweep_id = s.id), "
    "s.bench_name, s.bench_host, s.devices_json, s.key "
    "FROM sweeps s";
inline constexpr std::string_view kUpdateSweepStateSql =
    "UPDATE sweeps SET state = ?, started_at = ?, finished_at = ?, "
    "last_error = coalesce(?, last_error), owner_host = ?, owner_pid = ?, owner_start = ? WHERE id = ?";

// A JSON member as stored: SQL NULL for a JSON null.
inline std::optional<std::string> json_text(const synbench::Json& j) {
  if (j.is_null()) return std::nullopt;
  return j.dump();
}

template <class Row>
Result<synbench::Json> json_column(const Row& st, int i, std::string_view what) {
  if (st.is_null(i)) return synbench::Json(nullptr);
  auto j = synbench::Json::parse(st.text(i), nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return make_error(errc::bad_record, std::string(what) + " is not valid JSON");
  return j;
}

// A sweep from a row of kSweepColumns (a SQLite statement or a PostgreSQL row).
template <class Row>
Result<Sweep> read_sweep(const Row& st) {
  Sweep s;
  s.id = st.integer(0);
  s.meta.name = st.text(1);
  s.created_at = st.text(2);
  s.started_at = st.opt_text(3);
  s.finished_at = st.opt_text(4);
  const auto state = parse_sweep_state(st.text(5));
  if (!state) return make_error(errc::bad_record, "sweep " + std::to_string(s.id) + " has an unknown state");
  s.state = *state;
  const std::pair<int, synbench::Json SweepMeta::*> json_columns[] = {
      {6, &SweepMeta::plan}, {8, &SweepMeta::profiles}, {9, &SweepMeta::bench_config}, {10, &SweepMeta::calibration}};
  for (const auto& [col, member] : json_columns) {
    auto j = json_column(st, col, "a JSON column of sweep " + std::to_string(s.id));
    if (!j) return j.error();
    s.meta.*member = std::move(*j);
  }
  s.meta.software_version = st.text(7);
  s.meta.total_points = st.integer(11);
  s.last_error = st.opt_text(12);
  s.points_stored = st.integer(13);
  s.meta.bench_name = st.opt_text(14).value_or("");
  s.meta.bench_host = st.opt_text(15).value_or("");
  if (const auto devices = st.opt_text(16)) {
    auto d = parse_devices_json(*devices);
    if (!d) return make_error(errc::bad_record, "sweep " + std::to_string(s.id) + ": " + d.error().message);
    s.meta.devices = std::move(*d);
  }
  s.meta.key = st.opt_text(17);
  return s;
}

inline constexpr std::string_view kEventColumns = "SELECT id, sweep_id, at, kind, message FROM events";

// An event from a row of kEventColumns (a SQLite statement or a PostgreSQL row).
template <class Row>
Result<Event> read_event(const Row& st) {
  Event e;
  e.id = st.integer(0);
  if (!st.is_null(1)) e.sweep_id = st.integer(1);
  e.at = st.text(2);
  const auto kind = parse_event_kind(st.text(3));
  if (!kind) return make_error(errc::bad_record, "event " + std::to_string(e.id) + " has an unknown kind");
  e.kind = *kind;
  e.message = st.text(4);
  return e;
}

// The parameters of kInsertSweepSql, with the store's bench identity where the sweep has none.
template <class Params>
void bind_sweep(Params& st, const SweepMeta& meta, const BenchIdentity& bench, const std::string& now) {
  st.bind(1, meta.name);
  st.bind(2, now);
  st.bind(3, json_text(meta.plan));
  st.bind(4, meta.software_version);
  st.bind(5, json_text(meta.profiles));
  st.bind(6, json_text(meta.bench_config));
  st.bind(7, json_text(meta.calibration));
  st.bind(8, meta.total_points);
  st.bind(9, meta.bench_name.empty() ? bench.name : meta.bench_name);
  st.bind(10, meta.bench_host.empty() ? bench.host : meta.bench_host);
  st.bind(11, devices_json(meta.devices.empty() ? bench.devices : meta.devices));
  st.bind(12, meta.key);
}

// create_sweep's refusals before any SQL.
std::optional<Error> refuse_meta(const SweepMeta& meta);
Error duplicate_key(const std::string& key);

bool finished(SweepState s);
// set_sweep_state's refusal of the transition from -> to, if any (store.hpp).
std::optional<Error> refuse_transition(SweepState from, SweepState to, std::int64_t stored, std::int64_t total,
                                       bool sparse_plan);

// The stored indices (ascending, in 0 .. total-1) to the missing ones.
std::vector<std::int64_t> missing_from(std::int64_t total, const std::vector<std::int64_t>& stored);

}  // namespace synbench::db::detail
