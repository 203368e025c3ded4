// SQLite RAII helpers and the mapping of SQLite result codes to db::errc.
#include "db/sqlite.hpp"

#include <limits>

namespace synbench::db::detail {
namespace {

// SQLITE_TRANSIENT spelled without its old-style cast: SQLite copies the bytes during the bind,
// so callers may pass temporaries.
const sqlite3_destructor_type kTransient = reinterpret_cast<sqlite3_destructor_type>(-1);

int length(std::string_view v) {
  // SQLite lengths are int; anything longer is refused by SQLite's own limits long before this.
  return v.size() > static_cast<std::size_t>(std::numeric_limits<int>::max())
             ? std::numeric_limits<int>::max()
             : static_cast<int>(v.size());
}

}  // namespace

errc classify(int rc) noexcept {
  switch (rc & 0xff) {
    case SQLITE_OK:
    case SQLITE_ROW:
    case SQLITE_DONE: return errc::ok;
    case SQLITE_BUSY:
    case SQLITE_LOCKED: return errc::busy;
    case SQLITE_FULL: return errc::disk_full;
    case SQLITE_READONLY: return errc::read_only;
    case SQLITE_IOERR:
    case SQLITE_CANTOPEN:
    case SQLITE_PERM: return errc::io;
    case SQLITE_CORRUPT:
    case SQLITE_NOTADB: return errc::corrupt;
    default: return errc::sqlite;
  }
}

namespace {

// What an operator should read first, before SQLite's own sentence: SQLite says "database or
// disk is full" for both SQLITE_FULL causes and "attempt to write a readonly database" for
// several read-only causes.
std::string_view plain_words(int rc) noexcept {
  switch (rc & 0xff) {
    case SQLITE_FULL: return "disk full: ";
    case SQLITE_READONLY: return "read-only: ";
    case SQLITE_IOERR: return "I/O error: ";
    case SQLITE_CORRUPT: return "database damaged: ";
    default: return "";
  }
}

Error describe(int rc, std::string_view what, const char* sqlite_message) {
  std::string msg(what);
  msg += ": ";
  msg += plain_words(rc);
  msg += sqlite_message;
  // The extended code (sqlite3_extended_result_codes is on) tells e.g. SQLITE_IOERR_FSYNC (1034)
  // from SQLITE_IOERR_WRITE (778).
  msg += " (SQLite code " + std::to_string(rc) + ")";
  return {make_error_code(classify(rc)), std::move(msg)};
}

}  // namespace

Error sqlite_error(sqlite3* db, int rc, std::string_view what) {
  // The connection's message is the specific one ("UNIQUE constraint failed: ..."); without a
  // connection (open failed early) only the generic text of the code is known.
  return describe(rc, what, db ? sqlite3_errmsg(db) : sqlite3_errstr(rc));
}

Status exec(sqlite3* db, const char* sql, std::string_view what) {
  char* err = nullptr;
  const int rc = sqlite3_exec(db, sql, nullptr, nullptr, &err);
  if (rc == SQLITE_OK) return {};
  Error e = describe(rc, what, err ? err : sqlite3_errstr(rc));
  sqlite3_free(err);
  return e;
}

Result<Statement> Statement::prepare(sqlite3* db, std::string_view sql) {
  sqlite3_stmt* s = nullptr;
  const int rc = sqlite3_prepare_v3(db, sql.data(), length(sql), SQLITE_PREPARE_PERSISTENT, &s, nullptr);
  if (rc != SQLITE_OK) {
    sqlite3_finalize(s);
    return sqlite_error(db, rc, "preparing \"" + std::string(sql.substr(0, 60)) + "...\"");
  }
  return Statement(s);
}

Statement& Statement::operator=(Statement&& o) noexcept {
  if (this != &o) {
    sqlite3_finalize(stmt_);
    stmt_ = std::exchange(o.stmt_, nullptr);
  }
  return *this;
}

void Statement::bind_null(int i) { sqlite3_bind_null(stmt_, i); }
void Statement::bind(int i, double v) { sqlite3_bind_double(stmt_, i, v); }
void Statement::bind(int i, std::int64_t v) { sqlite3_bind_int64(stmt_, i, v); }
void Statement::bind(int i, std::string_view v) {
  sqlite3_bind_text(stmt_, i, v.data(), length(v), kTransient);
}
void Statement::bind(int i, const std::optional<double>& v) { v ? bind(i, *v) : bind_null(i); }
void Statement::bind(int i, const std::optional<std::int64_t>& v) { v ? bind(i, *v) : bind_null(i); }
void Statement::bind(int i, const std::optional<std::string>& v) {
  v ? bind(i, std::string_view(*v)) : bind_null(i);
}

std::string Statement::text(int i) const {
  const auto* p = sqlite3_column_text(stmt_, i);
  const int n = sqlite3_column_bytes(stmt_, i);  // after column_text, as SQLite requires
  return p ? std::string(reinterpret_cast<const char*>(p), static_cast<std::size_t>(n)) : std::string();
}

std::optional<std::string> Statement::opt_text(int i) const {
  if (is_null(i)) return std::nullopt;
  return text(i);
}

Result<TransactionStatements> TransactionStatements::prepare(sqlite3* db) {
  auto b = Statement::prepare(db, "BEGIN IMMEDIATE");
  if (!b) return b.error();
  auto c = Statement::prepare(db, "COMMIT");
  if (!c) return c.error();
  auto r = Statement::prepare(db, "ROLLBACK");
  if (!r) return r.error();
  return TransactionStatements{std::move(*b), std::move(*c), std::move(*r)};
}

Transaction::~Transaction() {
  // Only if still ours: a failed COMMIT may already have ended the transaction.
  if (open_ && sqlite3_get_autocommit(db_) == 0) {
    Statement::Use use(s_.rollback);
    s_.rollback.step();
  }
}

Status Transaction::run(Statement& s, std::string_view what) {
  Statement::Use use(s);
  const int rc = s.step();
  if (rc == SQLITE_DONE) return {};
  return sqlite_error(db_, rc, what);
}

Status Transaction::begin() {
  auto s = run(s_.begin, "starting a transaction");
  open_ = s.ok();
  return s;
}

Status Transaction::commit() {
  auto s = run(s_.commit, "committing");
  // On failure the destructor rolls back whatever is left, so nothing half-done survives.
  if (s.ok()) open_ = false;
  return s;
}

}  // namespace synbench::db::detail
