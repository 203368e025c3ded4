// Thin RAII over libpq, internal to db/: a connection, a query's result, text parameters and
// rows with the accessors point_columns.hpp's templates use (so a record binds and reads the
// same way on both backends), and the one place where SQLSTATEs become db::errc. No public
// header of db/ includes this (nor libpq-fe.h).
#pragma once

#include <libpq-fe.h>

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "db/error.hpp"

namespace synbench::db::detail {

// errc for a SQLSTATE (five characters; "" when the server sent none, as for a lost connection).
errc classify_sqlstate(std::string_view sqlstate) noexcept;

struct PgResultDeleter {
  void operator()(PGresult* r) const noexcept { PQclear(r); }
};
using PgResultPtr = std::unique_ptr<PGresult, PgResultDeleter>;

// Statement parameters in text form, 1-based like SQLite's. Doubles go as their shortest exact
// decimal (std::to_chars), so they read back bit for bit; NaN and nullopt become NULL as on
// SQLite (the record's NaN policy is one for both backends).
class PgParams {
 public:
  void bind_null(int i);
  void bind(int i, double v);
  void bind(int i, std::int64_t v);
  void bind(int i, std::string_view v);
  void bind(int i, const std::string& v) { bind(i, std::string_view(v)); }
  void bind(int i, const char* v) { bind(i, std::string_view(v)); }
  void bind(int i, const std::optional<double>& v);
  void bind(int i, const std::optional<std::int64_t>& v);
  void bind(int i, const std::optional<std::string>& v);

  int size() const noexcept { return static_cast<int>(values_.size()); }
  std::vector<const char*> pointers() const;

 private:
  std::optional<std::string>& at(int i);
  std::vector<std::optional<std::string>> values_;
};

// One row of a result, columns 0-based like SQLite's.
class PgRow {
 public:
  PgRow(const PGresult* r, int row) : r_(r), row_(row) {}
  bool is_null(int i) const { return PQgetisnull(r_, row_, i) != 0; }
  double real(int i) const;            // NaN, Infinity and -Infinity as PostgreSQL writes them
  std::int64_t integer(int i) const;
  std::string text(int i) const { return PQgetvalue(r_, row_, i); }
  std::optional<std::string> opt_text(int i) const;

 private:
  const PGresult* r_;
  int row_;
};

// A connection. `what` in each call says what we tried, for the message; errors carry the
// target (password redacted), libpq's text and the SQLSTATE.
class PgConnection {
 public:
  // conninfo: a postgresql:// URL or key=value pairs; `shown` is its redacted form.
  static Result<PgConnection> connect(const std::string& conninfo, std::string shown);
  PgConnection(PgConnection&&) noexcept = default;
  PgConnection& operator=(PgConnection&&) noexcept = default;
  ~PgConnection();

  // A command or query with parameters; a result that is neither COMMAND_OK nor TUPLES_OK is
  // an Error. A connection found broken is reset once before the query (a restarted server, a
  // dropped TCP link) so the next call after a connection_lost can succeed.
  Result<PgResultPtr> exec(std::string_view sql, const PgParams& params, std::string_view what);
  Result<PgResultPtr> exec(std::string_view sql, std::string_view what) { return exec(sql, PgParams{}, what); }
  // Several statements without parameters (DDL), in one round trip.
  Status exec_script(std::string_view sql, std::string_view what);

  // A SET run now and again after every reconnection (a reset session forgets its settings).
  Status set_session(std::string sql, std::string_view what);

  const std::string& shown() const noexcept { return shown_; }
  Error error(std::string_view what, const PGresult* r) const;

 private:
  struct Closer {
    void operator()(PGconn* c) const noexcept { PQfinish(c); }
  };
  PgConnection(std::unique_ptr<PGconn, Closer> c, std::string shown) : conn_(std::move(c)), shown_(std::move(shown)) {}
  std::unique_ptr<PGconn, Closer> conn_;
  std::string shown_;
  std::string session_;  // the SETs of every session, ';'-separated
};

// BEGIN ... COMMIT, rolled back if not committed (an early return on an error).
class PgTransaction {
 public:
  explicit PgTransaction(PgConnection& c) : c_(c) {}
  PgTransaction(const PgTransaction&) = delete;
  PgTransaction& operator=(const PgTransaction&) = delete;
  ~PgTransaction();
  Status begin(std::string_view what);
  Status commit(std::string_view what);

 private:
  PgConnection& c_;
  bool open_ = false;
};

}  // namespace synbench::db::detail
