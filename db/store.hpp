// synbench's store: sweeps with their metadata, one row per measured point, events. One type
// for the rest of synbench over two backends (db/backend.hpp): a SQLite file, the embedded
// default for one bench, or a PostgreSQL database, the lab store several benches write into
// (docs/database.md). The same schema and migrations on both; what follows is SQLite's side,
// and docs/database.md says where PostgreSQL differs (durability: COMMIT per point with the
// server's synchronous_commit; concurrency: row locks; no file_lost, pragmas or max_page_count).
//
// Durability: WAL with synchronous=FULL, and one transaction per point, so insert_point returns
// only once its point is on disk; a crash (process or power) loses at most the point in flight,
// and a sweep resumes at first_missing_index(). UNIQUE(sweep_id, point_index) makes a resumed
// sweep unable to store a point twice.
//
// Threads: a Store is one SQLite connection with its prepared statements and is used from one
// thread at a time (the one that owns it); it is movable, not copyable. Other processes or
// connections may read the same file concurrently (WAL); writers wait up to busy_timeout.
//
// Errors: every call returns Status or Result<T>; nothing throws except on programmer errors
// (reading the value of a failed Result, or calling anything on a moved-from Store). Messages
// name the file and carry SQLite's own text and extended code.
//
// A lost file: before each write transaction, after each commit and before each read, the store
// checks that the file (and its -wal, -shm) it has open is still the one at its path, and
// answers errc::file_lost once it was deleted or replaced: SQLite would go on committing into
// the unlinked file, and its points would vanish unseen.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "bench/point_record.hpp"
#include "db/error.hpp"
#include "db/types.hpp"

namespace synbench::db {

namespace detail {
class Backend;
}

// Wall-clock UTC with milliseconds, ISO 8601 ("2026-12-04T05:01:02.345Z"): the store's
// timestamps; sorts as text and SQLite's date functions read it.
std::string now_utc();

// Whether `target` names a PostgreSQL database rather than a file: a postgresql:// or
// postgres:// URL, or libpq's key=value form ("host=/run/pg dbname=lab"). A file whose name
// looks like the latter is reached as ./host=...
bool is_postgres_target(std::string_view target);
// `target` as it may be printed or logged: a URL's or key=value password as ***.
std::string shown_target(std::string_view target);

struct StoreOptions {
  int busy_timeout_ms = 5000;  // how long a write waits for another connection's lock
  // At open, PRAGMA quick_check (a file with damaged pages is refused, errc::corrupt) and a
  // committed write (a file that cannot be written is refused, errc::read_only). Costs a scan of
  // the file: for a process's start (the daemon, `synbench sweep`), not for every connection.
  bool verify = false;
  // SQLite's max_page_count for this connection, if set: a size limit, past which writes fail
  // with errc::disk_full as on a full disk (the tests' way to fill the disk). PostgreSQL
  // refuses it (errc::unsupported). busy_timeout_ms is its lock_timeout.
  std::optional<std::int64_t> max_page_count;
  // Told of every failure of the storage itself (is_storage_failure: SQLite, the file, the disk),
  // with the message the caller gets; not of refusals such as an unknown sweep. For the log.
  std::function<void(const Error&)> on_error;
  // The bench this process writes as: stamped on every sweep created without its own identity
  // (an empty SweepMeta::bench_name, bench_host or devices). Empty name and host default to
  // this machine's host name.
  BenchIdentity bench;
};

class Store {
 public:
  // Creates the file if needed, sets WAL, synchronous=FULL, foreign_keys and busy_timeout, and
  // applies pending migrations. Refuses a database newer than this code (errc::schema_too_new),
  // another application's database (errc::not_synbench), a file SQLite could open only for
  // reading (errc::read_only), and with options.verify a damaged (errc::corrupt) or unwritable
  // one.
  // A PostgreSQL target (is_postgres_target) connects, refuses a database of another application
  // (errc::not_synbench) or a newer schema, and migrates under an advisory lock; errors name
  // the target with its password redacted and carry libpq's text and SQLSTATE.
  static Result<Store> open(const std::filesystem::path& target, const StoreOptions& options = {});

  Store(Store&&) noexcept;
  Store& operator=(Store&&) noexcept;
  Store(const Store&) = delete;
  Store& operator=(const Store&) = delete;
  ~Store();

  enum class Kind { sqlite, postgres };
  Kind kind() const noexcept { return kind_; }
  // The file, or the PostgreSQL target with its password redacted.
  const std::filesystem::path& path() const;

  // --- sweeps ---
  // A new sweep in state `created` (and its `state` event), in one transaction. An empty bench
  // identity in `meta` is the store's (StoreOptions::bench). errc::duplicate_key if meta.key is
  // set and another sweep has it (nothing changes).
  Result<std::int64_t> create_sweep(const SweepMeta& meta);
  // The sweep created with this key, or nullopt.
  Result<std::optional<Sweep>> find_sweep_by_key(std::string_view key);
  // Changes the state, records a `state` event ("running -> paused: <error>") in the same
  // transaction, stamps started_at (first time running) and finished_at (completed, aborted,
  // faulted; cleared when resumed), and keeps `error` as last_error if given. Refuses
  // (errc::invalid_transition) leaving `completed`, returning to `created`, and `completed` while
  // points are missing.
  // `sparse_plan`: the plan does not need every index below total_points (an adaptive search
  // stops when it has found its optima), so `completed` does not wait for the gaps.
  Status set_sweep_state(std::int64_t sweep_id, SweepState state,
                         const std::optional<std::string>& error = std::nullopt,
                         bool sparse_plan = false);
  Result<Sweep> get_sweep(std::int64_t sweep_id);
  Result<std::vector<Sweep>> list_sweeps();  // by id
  // Sweeps in state `running` whose process is gone (it crashed, the machine restarted, or it
  // ran before owners were recorded) become `aborted`, each with the state event "running ->
  // aborted: marked aborted at start: left running by a previous process (pid 12 on host)", in
  // one transaction. A sweep whose process still runs (`synbench sweep` on the same file), or
  // runs where this process cannot see (another container), is left alone and reported.
  Result<std::vector<LeftRunning>> abort_left_running();

  // --- points ---
  // Stores one point in its own transaction, committed (fsynced) before returning.
  // errc::duplicate_point if (sweep_id, point_index) is already stored (nothing changes),
  // errc::not_found for an unknown sweep, errc::invalid_argument for an index outside
  // 0 .. total_points-1.
  Status insert_point(std::int64_t sweep_id, std::int64_t point_index, const bench::PointRecord& record);
  // All stored points of a sweep by index. Every field round-trips exactly, nulls and truth
  // included; the one loss is SQLite's: a NaN in an optional field reads back as null.
  Result<std::vector<PointRow>> points(std::int64_t sweep_id);
  // Plan indices 0 .. total_points-1 without a stored point, ascending.
  Result<std::vector<std::int64_t>> missing_indices(std::int64_t sweep_id);
  // Where a resumed sweep starts: the lowest missing index, or nullopt if the sweep is complete.
  Result<std::optional<std::int64_t>> first_missing_index(std::int64_t sweep_id);

  // --- events ---
  // sweep_id nullopt for a bench-wide event. Returns the event id.
  Result<std::int64_t> add_event(std::optional<std::int64_t> sweep_id, EventKind kind,
                                 std::string_view message);
  // One sweep's events (errc::not_found for an unknown sweep), or all events, bench-wide
  // included, for nullopt; oldest first.
  Result<std::vector<Event>> events(std::optional<std::int64_t> sweep_id = std::nullopt);

  // --- maintenance ---
  // PRAGMA integrity_check and foreign_key_check; errc::corrupt with their findings if not ok.
  // On PostgreSQL (which enforces its constraints on every write): orphan rows, unknown states.
  Status integrity_check();
  // The value of a pragma on this connection, as text (e.g. "wal", "2"); name is [a-z_]+.
  // errc::unsupported on PostgreSQL.
  Result<std::string> pragma(std::string_view name);

 private:
  Store(std::unique_ptr<detail::Backend> backend, std::string shown, Kind kind);
  detail::Backend& impl() const;
  std::unique_ptr<detail::Backend> backend_;
  std::filesystem::path path_;
  Kind kind_ = Kind::sqlite;
};

}  // namespace synbench::db
