// The database's error codes and the small Result type every Store call returns. SQLite has its
// own failure modes (a locked file, a full disk, a schema from a newer synbench, a duplicate
// point) that the device-side category in drivers/error.hpp has no words for, so db/ has its own
// category; the SQLite text travels next to the code in Error::message.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <variant>

namespace synbench::db {

enum class errc {
  ok = 0,
  sqlite = 1,          // SQLite reported a failure not classified below (see the message)
  busy,                // another connection held the database longer than busy_timeout
  io,                  // cannot open, read or write the file; disk full; read-only
  corrupt,             // not a database file, or integrity_check found damage
  schema_too_new,      // the file was migrated by a newer synbench than this one
  not_synbench,        // a SQLite database of some other application
  not_found,           // no sweep with that id
  duplicate_point,     // (sweep_id, point_index) is already stored; nothing was changed
  invalid_argument,    // e.g. a point index outside the sweep's plan, an empty sweep name
  invalid_transition,  // a sweep state change the store refuses (see docs/database.md)
  bad_record,          // a stored row cannot be turned back into a record (unknown estimator...)
  file_lost,           // the open file was deleted or replaced at its path: writes would vanish
  disk_full,           // SQLITE_FULL: no space left (or the connection's max_page_count)
  read_only,           // the file, its directory or its file system cannot be written
  duplicate_key,       // a sweep with that key is already stored; nothing was changed
  postgres,            // PostgreSQL reported a failure not classified here (message: text, SQLSTATE)
  connection_lost,     // the PostgreSQL server cannot be reached or closed the connection
  unsupported,         // a SQLite-only feature asked of PostgreSQL (pragma, max_page_count)
};

// Whether a failure is the database's (the file, the disk, SQLite) rather than the caller's
// (an unknown sweep, a duplicate point, a refused state change): these are worth a log line.
bool is_storage_failure(std::error_code ec) noexcept;

const std::error_category& error_category() noexcept;

inline std::error_code make_error_code(errc e) noexcept {
  return {static_cast<int>(e), error_category()};
}

// What failed: a code to branch on and a sentence for people (with SQLite's own text).
struct Error {
  std::error_code code;
  std::string message;
};

inline Error make_error(errc e, std::string message) { return {make_error_code(e), std::move(message)}; }

// A value or an Error. Reading the value of a failed Result is a programmer error and throws
// std::logic_error; everything the database or the caller's data can cause comes back as Error.
template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}        // NOLINT: implicit on purpose (return value;)
  Result(Error error) : v_(std::move(error)) {}    // NOLINT: implicit on purpose (return error;)

  bool ok() const noexcept { return v_.index() == 0; }
  explicit operator bool() const noexcept { return ok(); }

  T& value() & { check(); return std::get<0>(v_); }
  const T& value() const& { check(); return std::get<0>(v_); }
  T&& value() && { check(); return std::get<0>(std::move(v_)); }
  T& operator*() & { return value(); }
  const T& operator*() const& { return value(); }
  T* operator->() { return &value(); }
  const T* operator->() const { return &value(); }

  const Error& error() const {
    if (ok()) throw std::logic_error("db::Result::error() on a success");
    return std::get<1>(v_);
  }
  std::error_code code() const noexcept { return ok() ? std::error_code{} : std::get<1>(v_).code; }

 private:
  void check() const {
    if (!ok()) throw std::logic_error("db::Result::value() on an error: " + std::get<1>(v_).message);
  }
  std::variant<T, Error> v_;
};

// Success or an Error, for calls that return nothing.
class [[nodiscard]] Status {
 public:
  Status() = default;
  Status(Error error) : error_(std::move(error)) {}  // NOLINT: implicit on purpose

  bool ok() const noexcept { return !error_; }
  explicit operator bool() const noexcept { return ok(); }
  const Error& error() const {
    if (!error_) throw std::logic_error("db::Status::error() on a success");
    return *error_;
  }
  std::error_code code() const noexcept { return error_ ? error_->code : std::error_code{}; }

 private:
  std::optional<Error> error_;
};

}  // namespace synbench::db

template <>
struct std::is_error_code_enum<synbench::db::errc> : std::true_type {};
