// Thin RAII over the SQLite C API, internal to db/: a connection, prepared statements that are
// reset after every use, an IMMEDIATE transaction guard, and the one place where SQLite result
// codes become db::errc. No public header of db/ includes this (nor sqlite3.h).
#pragma once

#include <sqlite3.h>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "db/error.hpp"

namespace synbench::db::detail {

// SQLite's failure (rc, with the connection's message) as an Error; `what` says what we tried.
Error sqlite_error(sqlite3* db, int rc, std::string_view what);
errc classify(int rc) noexcept;

// Runs SQL without results (several statements allowed): DDL, pragmas, BEGIN/COMMIT.
Status exec(sqlite3* db, const char* sql, std::string_view what);

// A prepared statement, kept for the connection's life and reused: prepare once, then for each
// use bind, step, and let the Use guard reset it (so a half-read statement never holds a read
// transaction open).
class Statement {
 public:
  Statement() = default;
  static Result<Statement> prepare(sqlite3* db, std::string_view sql);
  Statement(Statement&& o) noexcept : stmt_(std::exchange(o.stmt_, nullptr)) {}
  Statement& operator=(Statement&& o) noexcept;
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  ~Statement() { sqlite3_finalize(stmt_); }

  sqlite3_stmt* get() const noexcept { return stmt_; }

  // Binding, 1-based as in SQLite. NaN and nullopt become NULL (SQLite stores NaN as NULL anyway).
  void bind_null(int i);
  void bind(int i, double v);
  void bind(int i, std::int64_t v);
  void bind(int i, std::string_view v);
  void bind(int i, const std::string& v) { bind(i, std::string_view(v)); }
  void bind(int i, const std::optional<double>& v);
  void bind(int i, const std::optional<std::int64_t>& v);
  void bind(int i, const std::optional<std::string>& v);

  int step() { return sqlite3_step(stmt_); }
  void reset() noexcept {
    sqlite3_reset(stmt_);
    sqlite3_clear_bindings(stmt_);
  }

  // Reading the current row, 0-based as in SQLite.
  bool is_null(int i) const { return sqlite3_column_type(stmt_, i) == SQLITE_NULL; }
  double real(int i) const { return sqlite3_column_double(stmt_, i); }
  std::int64_t integer(int i) const { return sqlite3_column_int64(stmt_, i); }
  std::string text(int i) const;
  std::optional<std::string> opt_text(int i) const;

  // Resets the statement when a use ends, whatever path the code takes out of it.
  class Use {
   public:
    explicit Use(Statement& s) : s_(s) {}
    ~Use() { s_.reset(); }
    Use(const Use&) = delete;
    Use& operator=(const Use&) = delete;

   private:
    Statement& s_;
  };

 private:
  explicit Statement(sqlite3_stmt* s) : stmt_(s) {}
  sqlite3_stmt* stmt_ = nullptr;
};

// BEGIN IMMEDIATE, COMMIT and ROLLBACK, prepared once per connection.
struct TransactionStatements {
  static Result<TransactionStatements> prepare(sqlite3* db);
  Statement begin, commit, rollback;
};

// BEGIN IMMEDIATE ... COMMIT. IMMEDIATE takes the write lock at the start, so a busy database is
// reported before any work and a read never has to be upgraded to a write mid-transaction.
// Destroyed without commit(), it rolls back.
class Transaction {
 public:
  Transaction(sqlite3* db, TransactionStatements& s) : db_(db), s_(s) {}
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  ~Transaction();

  Status begin();
  // Returns when the commit is durable (synchronous=FULL: the WAL is fsynced).
  Status commit();

 private:
  Status run(Statement& s, std::string_view what);
  sqlite3* db_;
  TransactionStatements& s_;
  bool open_ = false;
};

}  // namespace synbench::db::detail
