// libpq wrapper: connection, parameters in exact text form, rows, SQLSTATE classification.
#include "db/pg.hpp"

#include <charconv>
#include <cmath>
#include <limits>

namespace synbench::db::detail {

errc classify_sqlstate(std::string_view s) noexcept {
  if (s.empty()) return errc::connection_lost;  // no answer from a server at all
  const std::string_view cls = s.substr(0, 2);
  if (cls == "08" || s == "57P01" || s == "57P02" || s == "57P03") return errc::connection_lost;
  if (s == "23505") return errc::duplicate_point;  // the caller says which unique key
  if (s == "23503") return errc::not_found;        // a foreign key: no such sweep
  if (cls == "23" || cls == "22") return errc::invalid_argument;
  if (s == "40001" || s == "40P01" || s == "55P03" || s == "57014") return errc::busy;
  if (s == "53100") return errc::disk_full;
  if (s == "25006" || s == "42501") return errc::read_only;
  if (cls == "XX") return errc::corrupt;
  if (cls == "58") return errc::io;
  return errc::postgres;
}

// --- parameters ---

std::optional<std::string>& PgParams::at(int i) {
  if (static_cast<std::size_t>(i) > values_.size()) values_.resize(static_cast<std::size_t>(i));
  return values_[static_cast<std::size_t>(i - 1)];
}

void PgParams::bind_null(int i) { at(i).reset(); }

void PgParams::bind(int i, double v) {
  if (std::isnan(v)) return bind_null(i);
  if (std::isinf(v)) return bind(i, std::string_view(v > 0 ? "Infinity" : "-Infinity"));
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);  // shortest exact round trip
  at(i) = std::string(buf, r.ptr);
}

void PgParams::bind(int i, std::int64_t v) { at(i) = std::to_string(v); }
void PgParams::bind(int i, std::string_view v) { at(i) = std::string(v); }
void PgParams::bind(int i, const std::optional<double>& v) { v ? bind(i, *v) : bind_null(i); }
void PgParams::bind(int i, const std::optional<std::int64_t>& v) { v ? bind(i, *v) : bind_null(i); }
void PgParams::bind(int i, const std::optional<std::string>& v) { v ? bind(i, std::string_view(*v)) : bind_null(i); }

std::vector<const char*> PgParams::pointers() const {
  std::vector<const char*> out;
  for (const auto& v : values_) out.push_back(v ? v->c_str() : nullptr);
  return out;
}

// --- rows ---

double PgRow::real(int i) const {
  const std::string_view t = PQgetvalue(r_, row_, i);
  if (t == "NaN") return std::numeric_limits<double>::quiet_NaN();
  if (t == "Infinity") return std::numeric_limits<double>::infinity();
  if (t == "-Infinity") return -std::numeric_limits<double>::infinity();
  double v = 0;
  std::from_chars(t.data(), t.data() + t.size(), v);
  return v;
}

std::int64_t PgRow::integer(int i) const {
  const std::string_view t = PQgetvalue(r_, row_, i);
  std::int64_t v = 0;
  std::from_chars(t.data(), t.data() + t.size(), v);
  return v;
}

std::optional<std::string> PgRow::opt_text(int i) const {
  if (is_null(i)) return std::nullopt;
  return text(i);
}

// --- connection ---

Result<PgConnection> PgConnection::connect(const std::string& conninfo, std::string shown) {
  std::unique_ptr<PGconn, Closer> c(PQconnectdb(conninfo.c_str()));
  if (!c) return make_error(errc::connection_lost, shown + ": libpq could not allocate a connection");
  if (PQstatus(c.get()) != CONNECTION_OK) {
    std::string msg = PQerrorMessage(c.get());
    while (!msg.empty() && (msg.back() == '\n' || msg.back() == ' ')) msg.pop_back();
    return make_error(errc::connection_lost, shown + ": cannot connect: " + msg);
  }
  // Shortest exact float output (the default since PostgreSQL 12; set for older servers' sake),
  // UTC timestamps, and no notices on stderr (an "already exists" notice is not news).
  PQsetNoticeProcessor(c.get(), [](void*, const char*) {}, nullptr);
  PgConnection conn(std::move(c), std::move(shown));
  if (auto s = conn.set_session("SET extra_float_digits = 3; SET TIME ZONE 'UTC'", "setting up the session"); !s)
    return s.error();
  return conn;
}

PgConnection::~PgConnection() = default;

Error PgConnection::error(std::string_view what, const PGresult* r) const {
  const char* state = r ? PQresultErrorField(r, PG_DIAG_SQLSTATE) : nullptr;
  std::string msg = r ? PQresultErrorMessage(r) : "";
  if (msg.empty() && conn_) msg = PQerrorMessage(conn_.get());
  while (!msg.empty() && (msg.back() == '\n' || msg.back() == ' ')) msg.pop_back();
  const std::string sqlstate = state ? state : "";
  return make_error(classify_sqlstate(sqlstate), shown_ + ": " + std::string(what) + ": " + msg +
                                                     (sqlstate.empty() ? "" : " (SQLSTATE " + sqlstate + ")"));
}

Result<PgResultPtr> PgConnection::exec(std::string_view sql, const PgParams& params, std::string_view what) {
  if (PQstatus(conn_.get()) == CONNECTION_BAD) {
    PQreset(conn_.get());
    if (PQstatus(conn_.get()) != CONNECTION_OK) return error(what, nullptr);
    if (auto s = exec_script(session_, "setting up the session again"); !s) return s.error();
  }
  const std::string text(sql);
  const auto values = params.pointers();
  PgResultPtr r(params.size() == 0 && sql.find(';') != std::string_view::npos
                    ? PQexec(conn_.get(), text.c_str())
                    : PQexecParams(conn_.get(), text.c_str(), params.size(), nullptr,
                                   values.empty() ? nullptr : values.data(), nullptr, nullptr, 0));
  if (!r) return error(what, nullptr);
  const auto status = PQresultStatus(r.get());
  if (status != PGRES_COMMAND_OK && status != PGRES_TUPLES_OK) return error(what, r.get());
  return r;
}

Status PgConnection::set_session(std::string sql, std::string_view what) {
  if (auto s = exec_script(sql, what); !s) return s;
  session_ += (session_.empty() ? "" : "; ") + sql;
  return {};
}

Status PgConnection::exec_script(std::string_view sql, std::string_view what) {
  PgResultPtr r(PQexec(conn_.get(), std::string(sql).c_str()));
  if (!r) return error(what, nullptr);
  const auto status = PQresultStatus(r.get());
  if (status != PGRES_COMMAND_OK && status != PGRES_TUPLES_OK) return error(what, r.get());
  return {};
}

// --- transactions ---

PgTransaction::~PgTransaction() {
  if (open_) (void)c_.exec("ROLLBACK", "rolling back");
}

Status PgTransaction::begin(std::string_view what) {
  if (auto r = c_.exec("BEGIN", what); !r) return r.error();
  open_ = true;
  return {};
}

Status PgTransaction::commit(std::string_view what) {
  open_ = false;
  auto r = c_.exec("COMMIT", what);
  if (!r) return r.error();
  // COMMIT of a transaction a failed statement aborted answers "ROLLBACK", not an error.
  if (std::string_view(PQcmdStatus(r->get())) != "COMMIT")
    return make_error(errc::postgres, c_.shown() + ": " + std::string(what) + ": the transaction was rolled back");
  return {};
}

}  // namespace synbench::db::detail
