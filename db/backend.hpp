// What a storage backend does for db::Store, internal to db/: Store is the one type the rest of
// synbench uses, and forwards each call to its backend, SQLite (a file) or PostgreSQL (a
// server). Each member means what Store's member of the same name documents in store.hpp.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bench/point_record.hpp"
#include "db/error.hpp"
#include "db/types.hpp"

namespace synbench::db {
struct StoreOptions;
}

namespace synbench::db::detail {

class Backend {
 public:
  virtual ~Backend() = default;

  virtual Result<std::int64_t> create_sweep(const SweepMeta& meta) = 0;
  virtual Result<std::optional<Sweep>> find_sweep_by_key(std::string_view key) = 0;
  virtual Status set_sweep_state(std::int64_t sweep_id, SweepState state, const std::optional<std::string>& error,
                                 bool sparse_plan) = 0;
  virtual Result<Sweep> get_sweep(std::int64_t sweep_id) = 0;
  virtual Result<std::vector<Sweep>> list_sweeps() = 0;
  virtual Result<std::vector<LeftRunning>> abort_left_running() = 0;
  virtual Status insert_point(std::int64_t sweep_id, std::int64_t point_index, const bench::PointRecord& record) = 0;
  virtual Result<std::vector<PointRow>> points(std::int64_t sweep_id) = 0;
  virtual Result<std::vector<std::int64_t>> missing_indices(std::int64_t sweep_id) = 0;
  virtual Result<std::int64_t> add_event(std::optional<std::int64_t> sweep_id, EventKind kind,
                                         std::string_view message) = 0;
  virtual Result<std::vector<Event>> events(std::optional<std::int64_t> sweep_id) = 0;
  virtual Status integrity_check() = 0;
  virtual Result<std::string> pragma(std::string_view name) = 0;
};

Result<std::unique_ptr<Backend>> open_sqlite(const std::filesystem::path& path, const StoreOptions& options);
// `conninfo` as given (a URL or key=value pairs); `shown` is it with the password redacted.
Result<std::unique_ptr<Backend>> open_postgres(const std::string& conninfo, const std::string& shown,
                                               const StoreOptions& options);

}  // namespace synbench::db::detail
