// synbench's schema migrations and the loop that applies them.
#include "db/migrations.hpp"

#include <array>
#include <stdexcept>
#include <string>

#include "db/sqlite.hpp"

namespace synbench::db {
namespace {

// Version 1: sweeps, points, events. STRICT tables, so a value of the wrong type is refused.
// Point columns carry experiment.md Sec. 2.5's names in the record's order (tests/db checks them
// against the record's member table, bench/point_record_fields.hpp). The record's numbers are declared ANY with a typeof CHECK instead of
// REAL because REAL affinity stores integral values as integers and so turns -0.0 into 0.0; ANY
// keeps the exact double. They are nullable: optional fields are NULL when absent, and a NULL in a
// required field is a NaN (SQLite cannot store NaN). Estimator and PWM names are not CHECKed, so
// a new estimator needs no table rebuild; the store validates them when reading.
constexpr std::string_view kSchemaV1 = R"sql(
CREATE TABLE sweeps (
  id                INTEGER PRIMARY KEY,
  name              TEXT    NOT NULL,
  created_at        TEXT    NOT NULL,
  started_at        TEXT,
  finished_at       TEXT,
  state             TEXT    NOT NULL DEFAULT 'created'
                    CHECK (state IN ('created','running','paused','completed','aborted','faulted')),
  plan_json         TEXT,
  software_version  TEXT    NOT NULL,
  profiles_json     TEXT,
  bench_config_json TEXT,
  calibration_json  TEXT,
  total_points      INTEGER NOT NULL CHECK (total_points >= 0),
  last_error        TEXT
) STRICT;

CREATE TABLE points (
  id               INTEGER PRIMARY KEY,
  sweep_id         INTEGER NOT NULL REFERENCES sweeps(id) ON DELETE CASCADE,
  point_index      INTEGER NOT NULL CHECK (point_index >= 0),
  speed_rpm        ANY     CHECK (typeof(speed_rpm) IN ('real', 'null')),
  load_Nm          ANY     CHECK (typeof(load_Nm) IN ('real', 'null')),
  angle_deg        ANY     CHECK (typeof(angle_deg) IN ('real', 'null')),
  estimator        TEXT    NOT NULL,
  pwm              TEXT    NOT NULL,
  speed_meas_rpm   ANY     CHECK (typeof(speed_meas_rpm) IN ('real', 'null')),
  im_A             ANY     CHECK (typeof(im_A) IN ('real', 'null')),
  id_A             ANY     CHECK (typeof(id_A) IN ('real', 'null')),
  iq_A             ANY     CHECK (typeof(iq_A) IN ('real', 'null')),
  ud_V             ANY     CHECK (typeof(ud_V) IN ('real', 'null')),
  uq_V             ANY     CHECK (typeof(uq_V) IN ('real', 'null')),
  udc_V            ANY     CHECK (typeof(udc_V) IN ('real', 'null')),
  idcm_A           ANY     CHECK (typeof(idcm_A) IN ('real', 'null')),
  idcg_A           ANY     CHECK (typeof(idcg_A) IN ('real', 'null')),
  pdcm_W           ANY     CHECK (typeof(pdcm_W) IN ('real', 'null')),
  pdcg_W           ANY     CHECK (typeof(pdcg_W) IN ('real', 'null')),
  pm_W             ANY     CHECK (typeof(pm_W) IN ('real', 'null')),
  efficiency       ANY     CHECK (typeof(efficiency) IN ('real', 'null')),
  pos_err_min_deg  ANY     CHECK (typeof(pos_err_min_deg) IN ('real', 'null')),
  pos_err_mean_deg ANY     CHECK (typeof(pos_err_mean_deg) IN ('real', 'null')),
  pos_err_max_deg  ANY     CHECK (typeof(pos_err_max_deg) IN ('real', 'null')),
  speed_err_rpm    ANY     CHECK (typeof(speed_err_rpm) IN ('real', 'null')),
  ld_est_H         ANY     CHECK (typeof(ld_est_H) IN ('real', 'null')),
  lq_est_H         ANY     CHECK (typeof(lq_est_H) IN ('real', 'null')),
  rs_est_ohm       ANY     CHECK (typeof(rs_est_ohm) IN ('real', 'null')),
  ld_err_pct       ANY     CHECK (typeof(ld_err_pct) IN ('real', 'null')),
  lq_err_pct       ANY     CHECK (typeof(lq_err_pct) IN ('real', 'null')),
  rs_err_pct       ANY     CHECK (typeof(rs_err_pct) IN ('real', 'null')),
  temp_C           ANY     CHECK (typeof(temp_C) IN ('real', 'null')),
  window_s         ANY     CHECK (typeof(window_s) IN ('real', 'null')),
  samples          INTEGER NOT NULL CHECK (samples >= 0),
  settle_s         ANY     CHECK (typeof(settle_s) IN ('real', 'null')),
  voltage_limited  INTEGER NOT NULL CHECK (voltage_limited IN (0, 1)),
  unstable         INTEGER NOT NULL CHECK (unstable IN (0, 1)),
  fault            TEXT,
  truth_json       TEXT,
  measured_at      TEXT    NOT NULL,
  UNIQUE (sweep_id, point_index)
) STRICT;

CREATE TABLE events (
  id       INTEGER PRIMARY KEY,
  sweep_id INTEGER REFERENCES sweeps(id) ON DELETE CASCADE,
  at       TEXT    NOT NULL,
  kind     TEXT    NOT NULL CHECK (kind IN ('fault','state','log')),
  message  TEXT    NOT NULL
) STRICT;
CREATE INDEX events_by_sweep ON events (sweep_id, id);
)sql";

// Version 2: the estimator's minimum-speed flag and the share of the window on the low-speed
// fallback. Added columns follow measured_at; rows from version 1 ran without the flag (0). The
// default is the integer 0 (SQLite stores a 0.0 default in an ANY column as an integer, so the
// CHECK admits it; bound values are always reals, and an integer 0 reads back as 0.0).
constexpr std::string_view kSchemaV2 = R"sql(
ALTER TABLE points ADD COLUMN below_min_speed INTEGER NOT NULL DEFAULT 0 CHECK (below_min_speed IN (0, 1));
ALTER TABLE points ADD COLUMN fallback_fraction ANY DEFAULT 0 CHECK (typeof(fallback_fraction) IN ('real', 'integer', 'null'));
)sql";

// Version 3: the drive's lock guard ran the point on the encoder (the estimator lost the rotor).
// Rows from before ran without a guard (0).
constexpr std::string_view kSchemaV3 = R"sql(
ALTER TABLE points ADD COLUMN lock_lost INTEGER NOT NULL DEFAULT 0 CHECK (lock_lost IN (0, 1));
)sql";

// Version 4: the process driving a running sweep (host, pid, and its start: boot id and start
// time), so a daemon starting later can tell a sweep left running by a crash from one another
// process runs now. NULL when not running, and on sweeps of older versions.
constexpr std::string_view kSchemaV4 = R"sql(
ALTER TABLE sweeps ADD COLUMN owner_host TEXT;
ALTER TABLE sweeps ADD COLUMN owner_pid INTEGER;
ALTER TABLE sweeps ADD COLUMN owner_start TEXT;
)sql";

// Version 5: who kept the point's window: the device, or the bench from polled telemetry (a
// drive profile without window signals). Rows from before were all device-kept.
constexpr std::string_view kSchemaV5 = R"sql(
ALTER TABLE points ADD COLUMN window_source TEXT NOT NULL DEFAULT 'device' CHECK (window_source IN ('device', 'host'));
)sql";

// Version 6: the device's own code of a fault its profile has no label for (fault "unknown");
// NULL for every other fault and on rows from before.
constexpr std::string_view kSchemaV6 = R"sql(
ALTER TABLE points ADD COLUMN fault_code_raw INTEGER;
)sql";

// Version 7: the measured current angle of the window's mean (i_d, i_q) next to the requested
// one, and the flag that they disagree beyond the measurement's tolerance. Rows from before have
// no measured angle (NULL) and were never judged (0).
constexpr std::string_view kSchemaV7 = R"sql(
ALTER TABLE points ADD COLUMN angle_meas_deg ANY CHECK (typeof(angle_meas_deg) IN ('real', 'null'));
ALTER TABLE points ADD COLUMN angle_off INTEGER NOT NULL DEFAULT 0 CHECK (angle_off IN (0, 1));
)sql";

// Version 8: the standard uncertainties of the measured values (docs/uncertainty.md), combined
// and their point-to-point part. Rows from before have none (NULL).
constexpr std::string_view kSchemaV8 = R"sql(
ALTER TABLE points ADD COLUMN im_u_A ANY CHECK (typeof(im_u_A) IN ('real', 'null'));
ALTER TABLE points ADD COLUMN pdcm_u_W ANY CHECK (typeof(pdcm_u_W) IN ('real', 'null'));
ALTER TABLE points ADD COLUMN pdcg_u_W ANY CHECK (typeof(pdcg_u_W) IN ('real', 'null'));
ALTER TABLE points ADD COLUMN pm_u_W ANY CHECK (typeof(pm_u_W) IN ('real', 'null'));
ALTER TABLE points ADD COLUMN efficiency_u ANY CHECK (typeof(efficiency_u) IN ('real', 'null'));
ALTER TABLE points ADD COLUMN im_u_repeat_A ANY CHECK (typeof(im_u_repeat_A) IN ('real', 'null'));
ALTER TABLE points ADD COLUMN pdcm_u_repeat_W ANY CHECK (typeof(pdcm_u_repeat_W) IN ('real', 'null'));
ALTER TABLE points ADD COLUMN efficiency_u_repeat ANY CHECK (typeof(efficiency_u_repeat) IN ('real', 'null'));
)sql";

// Version 9: the bench's identity on every sweep (name, host, its devices' profiles and their
// versions as a JSON array) and an optional deterministic key a study shard finds its sweep
// again by: unique when set (SQLite's UNIQUE index admits any number of NULLs). Sweeps from
// before have no identity (NULL) and no key.
constexpr std::string_view kSchemaV9 = R"sql(
ALTER TABLE sweeps ADD COLUMN bench_name TEXT;
ALTER TABLE sweeps ADD COLUMN bench_host TEXT;
ALTER TABLE sweeps ADD COLUMN devices_json TEXT;
ALTER TABLE sweeps ADD COLUMN key TEXT;
CREATE UNIQUE INDEX sweeps_by_key ON sweeps (key);
)sql";

// --- PostgreSQL: the same steps in its dialect. Numbers are double precision (exact doubles,
// no affinity to work around); flags are smallint 0/1 as on SQLite, so both read the same way;
// timestamps are the store's ISO 8601 text on both. Unquoted names fold to lower case
// (load_nm), which the store never sees: it reads columns by position.

constexpr std::string_view kPgV1 = R"sql(
CREATE TABLE sweeps (
  id                bigint GENERATED BY DEFAULT AS IDENTITY PRIMARY KEY,
  name              text    NOT NULL,
  created_at        text    NOT NULL,
  started_at        text,
  finished_at       text,
  state             text    NOT NULL DEFAULT 'created'
                    CHECK (state IN ('created','running','paused','completed','aborted','faulted')),
  plan_json         text,
  software_version  text    NOT NULL,
  profiles_json     text,
  bench_config_json text,
  calibration_json  text,
  total_points      bigint  NOT NULL CHECK (total_points >= 0),
  last_error        text
);

CREATE TABLE points (
  id               bigint GENERATED BY DEFAULT AS IDENTITY PRIMARY KEY,
  sweep_id         bigint  NOT NULL REFERENCES sweeps(id) ON DELETE CASCADE,
  point_index      bigint  NOT NULL CHECK (point_index >= 0),
  speed_rpm        double precision,
  load_Nm          double precision,
  angle_deg        double precision,
  estimator        text    NOT NULL,
  pwm              text    NOT NULL,
  speed_meas_rpm   double precision,
  im_A             double precision,
  id_A             double precision,
  iq_A             double precision,
  ud_V             double precision,
  uq_V             double precision,
  udc_V            double precision,
  idcm_A           double precision,
  idcg_A           double precision,
  pdcm_W           double precision,
  pdcg_W           double precision,
  pm_W             double precision,
  efficiency       double precision,
  pos_err_min_deg  double precision,
  pos_err_mean_deg double precision,
  pos_err_max_deg  double precision,
  speed_err_rpm    double precision,
  ld_est_H         double precision,
  lq_est_H         double precision,
  rs_est_ohm       double precision,
  ld_err_pct       double precision,
  lq_err_pct       double precision,
  rs_err_pct       double precision,
  temp_C           double precision,
  window_s         double precision,
  samples          bigint   NOT NULL CHECK (samples >= 0),
  settle_s         double precision,
  voltage_limited  smallint NOT NULL CHECK (voltage_limited IN (0, 1)),
  unstable         smallint NOT NULL CHECK (unstable IN (0, 1)),
  fault            text,
  truth_json       text,
  measured_at      text     NOT NULL,
  UNIQUE (sweep_id, point_index)
);

CREATE TABLE events (
  id       bigint GENERATED BY DEFAULT AS IDENTITY PRIMARY KEY,
  sweep_id bigint REFERENCES sweeps(id) ON DELETE CASCADE,
  at       text NOT NULL,
  kind     text NOT NULL CHECK (kind IN ('fault','state','log')),
  message  text NOT NULL
);
CREATE INDEX events_by_sweep ON events (sweep_id, id);
)sql";

constexpr std::string_view kPgV2 = R"sql(
ALTER TABLE points ADD COLUMN below_min_speed smallint NOT NULL DEFAULT 0 CHECK (below_min_speed IN (0, 1));
ALTER TABLE points ADD COLUMN fallback_fraction double precision DEFAULT 0;
)sql";

constexpr std::string_view kPgV3 = R"sql(
ALTER TABLE points ADD COLUMN lock_lost smallint NOT NULL DEFAULT 0 CHECK (lock_lost IN (0, 1));
)sql";

constexpr std::string_view kPgV4 = R"sql(
ALTER TABLE sweeps ADD COLUMN owner_host text;
ALTER TABLE sweeps ADD COLUMN owner_pid bigint;
ALTER TABLE sweeps ADD COLUMN owner_start text;
)sql";

constexpr std::string_view kPgV5 = R"sql(
ALTER TABLE points ADD COLUMN window_source text NOT NULL DEFAULT 'device' CHECK (window_source IN ('device', 'host'));
)sql";

constexpr std::string_view kPgV6 = R"sql(
ALTER TABLE points ADD COLUMN fault_code_raw bigint;
)sql";

constexpr std::string_view kPgV7 = R"sql(
ALTER TABLE points ADD COLUMN angle_meas_deg double precision;
ALTER TABLE points ADD COLUMN angle_off smallint NOT NULL DEFAULT 0 CHECK (angle_off IN (0, 1));
)sql";

constexpr std::string_view kPgV8 = R"sql(
ALTER TABLE points ADD COLUMN im_u_A double precision;
ALTER TABLE points ADD COLUMN pdcm_u_W double precision;
ALTER TABLE points ADD COLUMN pdcg_u_W double precision;
ALTER TABLE points ADD COLUMN pm_u_W double precision;
ALTER TABLE points ADD COLUMN efficiency_u double precision;
ALTER TABLE points ADD COLUMN im_u_repeat_A double precision;
ALTER TABLE points ADD COLUMN pdcm_u_repeat_W double precision;
ALTER TABLE points ADD COLUMN efficiency_u_repeat double precision;
)sql";

// PostgreSQL's UNIQUE admits any number of NULLs too (NULLS DISTINCT, the default).
constexpr std::string_view kPgV9 = R"sql(
ALTER TABLE sweeps ADD COLUMN bench_name text;
ALTER TABLE sweeps ADD COLUMN bench_host text;
ALTER TABLE sweeps ADD COLUMN devices_json text;
ALTER TABLE sweeps ADD COLUMN key text;
CREATE UNIQUE INDEX sweeps_by_key ON sweeps (key);
)sql";

constexpr std::array kMigrations{
    Migration{1, "sweeps, points (experiment.md Sec. 2.5 fields), events", kSchemaV1, kPgV1},
    Migration{2, "points: below_min_speed, fallback_fraction", kSchemaV2, kPgV2},
    Migration{3, "points: lock_lost", kSchemaV3, kPgV3},
    Migration{4, "sweeps: owner_host, owner_pid, owner_start", kSchemaV4, kPgV4},
    Migration{5, "points: window_source", kSchemaV5, kPgV5},
    Migration{6, "points: fault_code_raw", kSchemaV6, kPgV6},
    Migration{7, "points: angle_meas_deg, angle_off", kSchemaV7, kPgV7},
    Migration{8, "points: im_u_A, pdcm_u_W, pdcg_u_W, pm_u_W, efficiency_u and their _u_repeat parts", kSchemaV8, kPgV8},
    Migration{9, "sweeps: bench_name, bench_host, devices_json, key (unique when set)", kSchemaV9, kPgV9},
};

struct Header {
  int user_version = 0;
  std::int64_t application_id = 0;
  std::int64_t objects = 0;  // tables, indexes, ... already in the file
};

Result<std::int64_t> scalar(sqlite3* db, std::string_view sql) {
  auto st = detail::Statement::prepare(db, sql);
  if (!st) return st.error();
  const int rc = st->step();
  if (rc != SQLITE_ROW) return detail::sqlite_error(db, rc, "reading the schema version");
  return st->integer(0);
}

Result<Header> read_header(sqlite3* db) {
  Header h;
  auto v = scalar(db, "PRAGMA user_version");
  if (!v) return v.error();
  auto a = scalar(db, "PRAGMA application_id");
  if (!a) return a.error();
  auto n = scalar(db, "SELECT count(*) FROM sqlite_schema");
  if (!n) return n.error();
  h.user_version = static_cast<int>(*v);
  h.application_id = *a;
  h.objects = *n;
  return h;
}

}  // namespace

std::span<const Migration> migrations() noexcept { return kMigrations; }

int schema_version() noexcept { return kMigrations.back().version; }

namespace detail {

Status migrate(sqlite3* db, std::span<const Migration> steps) {
  for (std::size_t i = 0; i < steps.size(); ++i)
    if (steps[i].version != static_cast<int>(i) + 1)
      throw std::logic_error("db migrations must be numbered 1, 2, 3, ... in order");
  const int latest = steps.empty() ? 0 : steps.back().version;

  auto tx_statements = TransactionStatements::prepare(db);
  if (!tx_statements) return tx_statements.error();
  for (;;) {
    Transaction tx(db, *tx_statements);
    if (auto s = tx.begin(); !s) return s;
    auto h = read_header(db);
    if (!h) return h.error();

    if (h->user_version > latest)
      return make_error(errc::schema_too_new,
                        "database schema version " + std::to_string(h->user_version) +
                            " is newer than this synbench understands (up to " +
                            std::to_string(latest) + "); use a newer synbench to open it");
    // A synbench file carries our application_id from step 1 on. A file without it is only ours
    // to initialise if it is empty (a brand-new file, or one whose first step was rolled back).
    const bool ours = h->application_id == kApplicationId;
    const bool empty = h->application_id == 0 && h->user_version == 0 && h->objects == 0;
    if (!ours && !empty)
      return make_error(errc::not_synbench,
                        "the file is a SQLite database of another application (application_id " +
                            std::to_string(h->application_id) + ", user_version " +
                            std::to_string(h->user_version) + ")");
    if (h->user_version == latest) return tx.commit();  // up to date: ends the read

    const Migration& step = steps[static_cast<std::size_t>(h->user_version)];
    const std::string where = "migration to schema version " + std::to_string(step.version);
    if (auto s = exec(db, std::string(step.sql).c_str(), where); !s) return s;
    // Both pragmas are written in the transaction, so a crash leaves the old version or the new,
    // never the new tables under the old number.
    const std::string mark = "PRAGMA user_version = " + std::to_string(step.version) +
                             "; PRAGMA application_id = " + std::to_string(kApplicationId) + ";";
    if (auto s = exec(db, mark.c_str(), where); !s) return s;
    if (auto s = tx.commit(); !s) return s;
  }
}

}  // namespace detail
}  // namespace synbench::db
