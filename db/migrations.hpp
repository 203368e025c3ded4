// The database schema as an ordered list of migrations, tracked by PRAGMA user_version on
// SQLite and by the synbench_schema table on PostgreSQL. Step N takes a database from version
// N-1 to N in one transaction. Each step carries both dialects side by side, so a step cannot
// be added for one backend only. Steps are history: once released, a step's SQL never changes;
// a schema change is a new step at the end.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>

#include "db/error.hpp"

struct sqlite3;

namespace synbench::db {

struct Migration {
  int version;                   // user_version after this step: 1, 2, 3, ...
  std::string_view description;  // one line, for people reading the code and the docs
  std::string_view sql;          // SQLite: one or more statements, run inside the step's transaction
  std::string_view pg_sql;       // PostgreSQL: the same step in its dialect
};

// synbench's migrations, in order.
std::span<const Migration> migrations() noexcept;
// The version this code writes and understands: the last step's version.
int schema_version() noexcept;

// PRAGMA application_id of a synbench database ("SYNB"), so another application's SQLite file
// is refused instead of being migrated.
inline constexpr std::int32_t kApplicationId = 0x53594E42;

namespace detail {
// Brings db up to steps.back().version, one transaction per step. Refuses (without changing the
// file) a database newer than the steps (errc::schema_too_new) or not created by synbench
// (errc::not_synbench). Safe against another process migrating the same file at the same time:
// each step re-reads the version inside its write transaction. Exposed for the tests.
Status migrate(sqlite3* db, std::span<const Migration> steps);
}  // namespace detail

}  // namespace synbench::db
