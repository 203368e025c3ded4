// Messages of the database's error category.
#include "db/error.hpp"

namespace synbench::db {
namespace {

class Category final : public std::error_category {
 public:
  const char* name() const noexcept override { return "synbench.db"; }
  std::string message(int ev) const override {
    switch (static_cast<errc>(ev)) {
      case errc::ok: return "ok";
      case errc::sqlite: return "SQLite error";
      case errc::busy: return "database is locked by another connection";
      case errc::io: return "cannot read or write the database file";
      case errc::corrupt: return "database file is damaged or not a database";
      case errc::schema_too_new: return "database was written by a newer synbench";
      case errc::not_synbench: return "not a synbench database";
      case errc::not_found: return "no such sweep";
      case errc::duplicate_point: return "point already stored";
      case errc::invalid_argument: return "invalid argument";
      case errc::invalid_transition: return "sweep state change refused";
      case errc::bad_record: return "stored row cannot be read back as a record";
      case errc::file_lost: return "the database file was deleted or replaced while open";
      case errc::disk_full: return "disk full";
      case errc::read_only: return "the database cannot be written (read-only)";
      case errc::duplicate_key: return "a sweep with that key is already stored";
      case errc::postgres: return "PostgreSQL error";
      case errc::connection_lost: return "connection to the PostgreSQL server lost";
      case errc::unsupported: return "not supported by this database backend";
    }
    return "unknown database error";
  }
};

}  // namespace

const std::error_category& error_category() noexcept {
  static const Category category;
  return category;
}

bool is_storage_failure(std::error_code ec) noexcept {
  if (ec.category() != error_category()) return false;
  switch (static_cast<errc>(ec.value())) {
    case errc::sqlite:
    case errc::busy:
    case errc::io:
    case errc::corrupt:
    case errc::bad_record:
    case errc::file_lost:
    case errc::disk_full:
    case errc::read_only:
    case errc::postgres:
    case errc::connection_lost: return true;
    default: return false;
  }
}

}  // namespace synbench::db
