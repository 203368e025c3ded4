// The SQLite backend of db::Store: opening and configuring the connection, sweeps, points,
// events. Store (store.hpp) documents what each call promises.
#include "db/store.hpp"

#include <chrono>
#include <ctime>
#include <stdexcept>
#include <thread>

#include "db/backend.hpp"
#include "db/bench_identity.hpp"
#include "db/file_watch.hpp"
#include "db/migrations.hpp"
#include "db/owner.hpp"
#include "db/point_columns.hpp"
#include "db/sqlite.hpp"
#include "db/sweep_rows.hpp"

namespace synbench::db::detail {


namespace {


constexpr std::string_view kRunningSql =
    "SELECT id, owner_host, owner_pid, owner_start FROM sweeps WHERE state = 'running' ORDER BY id";

}  // namespace

class SqliteBackend final : public Backend {
 public:
  Result<std::int64_t> create_sweep(const SweepMeta& meta) override;
  Result<std::optional<Sweep>> find_sweep_by_key(std::string_view key) override;
  Status set_sweep_state(std::int64_t sweep_id, SweepState state, const std::optional<std::string>& error,
                         bool sparse_plan) override;
  Result<Sweep> get_sweep(std::int64_t sweep_id) override;
  Result<std::vector<Sweep>> list_sweeps() override;
  Result<std::vector<LeftRunning>> abort_left_running() override;
  Status insert_point(std::int64_t sweep_id, std::int64_t point_index, const bench::PointRecord& record) override;
  Result<std::vector<PointRow>> points(std::int64_t sweep_id) override;
  Result<std::vector<std::int64_t>> missing_indices(std::int64_t sweep_id) override;
  Result<std::int64_t> add_event(std::optional<std::int64_t> sweep_id, EventKind kind,
                                 std::string_view message) override;
  Result<std::vector<Event>> events(std::optional<std::int64_t> sweep_id) override;
  Status integrity_check() override;
  Result<std::string> pragma(std::string_view name) override;

  sqlite3* db = nullptr;
  std::filesystem::path path;
  FileWatch watch;
  ProcessOwner me = this_process();
  std::function<void(const Error&)> on_error;
  BenchIdentity bench;
  TransactionStatements tx_statements;
  Statement insert_sweep, insert_event, sweep_for_update, update_sweep_state, select_sweep,
      select_sweeps, sweep_total, sweep_exists, insert_point_st, select_points, select_indices,
      select_events_of_sweep, select_events_all, select_running, select_sweep_by_key;

  ~SqliteBackend() override {
    // Statements first: sqlite3_close_v2 would otherwise defer the close until they are gone.
    tx_statements = {};
    for (auto* s : {&insert_sweep, &insert_event, &sweep_for_update, &update_sweep_state, &select_sweep,
                    &select_sweeps, &sweep_total, &sweep_exists, &insert_point_st, &select_points,
                    &select_indices, &select_events_of_sweep, &select_events_all, &select_running,
                    &select_sweep_by_key})
      *s = Statement();
    sqlite3_close_v2(db);
  }

  // A failure of the storage goes to the log hook on its way to the caller.
  Error report(Error e) const {
    if (on_error && is_storage_failure(e.code)) on_error(e);
    return e;
  }
  // SQLite's failure, naming the file and what we tried.
  Error fail(int rc, std::string_view what) const {
    return report(sqlite_error(db, rc, path.string() + ": " + std::string(what)));
  }
  Error named(const Error& e, std::string_view what) const {
    return report(Error{e.code, path.string() + ": " + std::string(what) + ": " + e.message});
  }
  // The file (and its WAL) at the path is still the one open: else errc::file_lost.
  Status check_file() {
    if (auto s = watch.check(); !s) return report(s.error());
    return {};
  }
  // BEGIN IMMEDIATE, refused before any work when the file is lost.
  Status begin(Transaction& t, std::string_view what) {
    if (auto s = check_file(); !s) return s;
    if (auto s = t.begin(); !s) return named(s.error(), what);
    return {};
  }
  // COMMIT, then the check again: a success means the data is in the file at the path, not in
  // one deleted while the commit ran.
  Status commit(Transaction& t, std::string_view what) {
    if (auto s = t.commit(); !s) return named(s.error(), what);
    return check_file();
  }

  Status prepare_all() {
    const std::pair<Statement*, std::string> all[] = {
        {&insert_sweep, std::string(kInsertSweepSql)},
        {&insert_event, "INSERT INTO events (sweep_id, at, kind, message) VALUES (?, ?, ?, ?)"},
        {&sweep_for_update,
         "SELECT state, started_at, total_points, (SELECT count(*) FROM points WHERE sweep_id = ?1) "
         "FROM sweeps WHERE id = ?1"},
        {&update_sweep_state, std::string(kUpdateSweepStateSql)},
        {&select_sweep, std::string(kSweepColumns) + " WHERE s.id = ?"},
        {&select_sweeps, std::string(kSweepColumns) + " ORDER BY s.id"},
        {&select_sweep_by_key, std::string(kSweepColumns) + " WHERE s.key = ?"},
        {&sweep_total, "SELECT total_points FROM sweeps WHERE id = ?"},
        {&sweep_exists, "SELECT 1 FROM sweeps WHERE id = ?"},
        {&insert_point_st, insert_point_sql()},
        {&select_points, select_points_sql()},
        {&select_indices, "SELECT point_index FROM points WHERE sweep_id = ? ORDER BY point_index"},
        {&select_events_of_sweep, std::string(kEventColumns) + " WHERE sweep_id = ? ORDER BY id"},
        {&select_events_all, std::string(kEventColumns) + " ORDER BY id"},
        {&select_running, std::string(kRunningSql)},
    };
    for (const auto& [st, sql] : all) {
      auto p = Statement::prepare(db, sql);
      if (!p) return p.error();
      *st = std::move(*p);
    }
    auto t = TransactionStatements::prepare(db);
    if (!t) return t.error();
    tx_statements = std::move(*t);
    return {};
  }

  // Whether the sweep exists; a database failure is an Error.
  Result<bool> exists(std::int64_t sweep_id) {
    Statement::Use use(sweep_exists);
    sweep_exists.bind(1, sweep_id);
    const int rc = sweep_exists.step();
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    return fail(rc, "looking up the sweep");
  }

  Status add_event_in_tx(std::optional<std::int64_t> sweep_id, EventKind kind, std::string_view message,
                         std::int64_t* id) {
    Statement::Use use(insert_event);
    insert_event.bind(1, sweep_id);
    insert_event.bind(2, now_utc());
    insert_event.bind(3, name(kind));
    insert_event.bind(4, message);
    const int rc = insert_event.step();
    if (rc == SQLITE_CONSTRAINT_FOREIGNKEY)
      return make_error(errc::not_found, "no sweep " + std::to_string(sweep_id.value_or(0)));
    if (rc != SQLITE_DONE) return fail(rc, "recording an event");
    if (id) *id = sqlite3_last_insert_rowid(db);
    return {};
  }

  // The body of set_sweep_state, inside the caller's transaction. A sweep going running records
  // this process as its owner; leaving running clears it.
  Status change_state_in_tx(std::int64_t sweep_id, SweepState state, const std::optional<std::string>& error,
                            bool sparse_plan) {
    SweepState from{};
    std::optional<std::string> started_at;
    std::int64_t total = 0, stored = 0;
    {
      auto& st = sweep_for_update;
      Statement::Use use(st);
      st.bind(1, sweep_id);
      const int rc = st.step();
      if (rc == SQLITE_DONE) return make_error(errc::not_found, "no sweep " + std::to_string(sweep_id));
      if (rc != SQLITE_ROW) return fail(rc, "reading the sweep's state");
      const auto f = parse_sweep_state(st.text(0));
      if (!f) return make_error(errc::bad_record, "sweep " + std::to_string(sweep_id) + " has an unknown state");
      from = *f;
      started_at = st.opt_text(1);
      total = st.integer(2);
      stored = st.integer(3);
    }
    if (auto refused = refuse_transition(from, state, stored, total, sparse_plan)) return *refused;
    const std::string transition = std::string(name(from)) + " -> " + std::string(name(state));

    const std::string now = now_utc();
    if (state == SweepState::running && !started_at) started_at = now;
    const bool running = state == SweepState::running;
    {
      auto& st = update_sweep_state;
      Statement::Use use(st);
      st.bind(1, name(state));
      st.bind(2, started_at);
      st.bind(3, finished(state) ? std::optional<std::string>(now) : std::nullopt);
      st.bind(4, error);
      st.bind(5, running ? std::optional<std::string>(me.host) : std::nullopt);
      st.bind(6, running ? std::optional<std::int64_t>(me.pid) : std::nullopt);
      st.bind(7, running && !me.start.empty() ? std::optional<std::string>(me.start) : std::nullopt);
      st.bind(8, sweep_id);
      const int rc = st.step();
      if (rc != SQLITE_DONE) return fail(rc, "changing the sweep's state");
    }
    const std::string message = error ? transition + ": " + *error : transition;
    return add_event_in_tx(sweep_id, EventKind::state, message, nullptr);
  }
};

namespace {

// A read-only refusal, with the places to look.
Error read_only_error(const std::string& message) {
  return make_error(errc::read_only, message +
                                         "; synbench must write it (check the file's mode and owner, its directory's, "
                                         "and whether the file system is mounted read-only)");
}

// PRAGMA quick_check: the b-trees' pages and records, without the index cross-checks of
// integrity_check, so it stays quick on a large file. Up to 10 findings in the message.
Status quick_check(sqlite3* db, const std::string& where) {
  auto st = Statement::prepare(db, "PRAGMA quick_check(10)");
  if (!st) return Error{st.error().code, where + ": quick_check: " + st.error().message};
  std::string findings;
  for (;;) {
    const int rc = st->step();
    if (rc == SQLITE_DONE) break;
    if (rc != SQLITE_ROW) return sqlite_error(db, rc, where + ": quick_check");
    const std::string row = st->text(0);
    if (row == "ok") continue;
    findings += findings.empty() ? "" : "; ";
    findings += row;
  }
  if (findings.empty()) return {};
  return make_error(errc::corrupt, where + ": the file has damaged pages; PRAGMA quick_check says: " + findings);
}

}  // namespace

Result<std::unique_ptr<Backend>> open_sqlite(const std::filesystem::path& path, const StoreOptions& options) {
  // SQLite would take "" as a private temporary database, gone at close: never what is meant.
  if (path.empty()) return make_error(errc::invalid_argument, "the database path is empty");
  auto impl = std::make_unique<SqliteBackend>();
  impl->path = path;
  const std::string where = "opening " + path.string();
  // A read-only refusal also says where to look.
  const auto refuse = [&](Error e) -> Error {
    if (e.code == errc::read_only) return read_only_error(e.message);
    return e;
  };
  const int rc = sqlite3_open_v2(path.c_str(), &impl->db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr);
  if (rc != SQLITE_OK) return sqlite_error(impl->db, rc, where);
  sqlite3_extended_result_codes(impl->db, 1);  // tells a UNIQUE from a FOREIGN KEY failure
  sqlite3_busy_timeout(impl->db, options.busy_timeout_ms);

  // journal_mode answers with the mode it got: anything but "wal" (an in-memory database, a
  // file system without shared memory) would silently lose the durability we promise.
  {
    auto st = Statement::prepare(impl->db, "PRAGMA journal_mode = WAL");
    if (!st) return refuse(Error{st.error().code, where + ": " + st.error().message});
    // Two processes switching a new file to WAL at once: SQLite answers SQLITE_BUSY to one of
    // them without calling the busy handler (it would deadlock on the lock upgrade), so the wait
    // busy_timeout promises is kept here (several study shards opening one new file).
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::milliseconds(options.busy_timeout_ms);
    int step = st->step();
    while ((step == SQLITE_BUSY || step == SQLITE_LOCKED) && std::chrono::steady_clock::now() < give_up) {
      st->reset();
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      step = st->step();
    }
    if (step != SQLITE_ROW) return refuse(sqlite_error(impl->db, step, where + ": setting WAL"));
    if (st->text(0) != "wal")
      return make_error(errc::io, where + ": WAL journal not available (got \"" + st->text(0) + "\")");
  }
  // SQLite opens a file it may not write read-only without a word (SQLITE_OPEN_READWRITE means
  // "if possible"); every write would fail later, in the middle of a sweep.
  if (sqlite3_db_readonly(impl->db, "main") == 1)
    return read_only_error(where + ": SQLite could open the file only for reading");
  // synchronous=FULL: in WAL mode the WAL is fsynced at every commit, so a committed point
  // survives a power cut, not only a process crash (NORMAL would only promise the latter).
  if (auto s = exec(impl->db, "PRAGMA synchronous = FULL; PRAGMA foreign_keys = ON;", where); !s)
    return refuse(s.error());
  // Damaged pages are refused before a migration writes into the file.
  if (options.verify)
    if (auto s = quick_check(impl->db, where); !s) return s.error();
  if (auto s = migrate(impl->db, migrations()); !s)
    return refuse(Error{s.error().code, where + ": " + s.error().message});
  if (options.verify) {
    // A committed write (the version number, rewritten as it is): the WAL and its index must be
    // writable too, which the file's own mode does not tell.
    const std::string probe =
        "BEGIN IMMEDIATE; PRAGMA user_version = " + std::to_string(schema_version()) + "; COMMIT;";
    if (auto s = exec(impl->db, probe.c_str(), where + ": writing"); !s) {
      (void)exec(impl->db, "ROLLBACK", where);
      return refuse(s.error());
    }
  }
  if (options.max_page_count) {
    const std::string sql = "PRAGMA max_page_count = " + std::to_string(*options.max_page_count);
    if (auto s = exec(impl->db, sql.c_str(), where); !s) return s.error();
  }
  if (auto s = impl->prepare_all(); !s) return Error{s.error().code, where + ": " + s.error().message};
  auto watch = FileWatch::pin(impl->db, path);
  if (!watch) return Error{watch.error().code, where + ": " + watch.error().message};
  impl->watch = std::move(*watch);
  impl->on_error = options.on_error;
  impl->bench = resolved(options.bench);
  return std::unique_ptr<Backend>(std::move(impl));
}

Result<std::int64_t> SqliteBackend::create_sweep(const SweepMeta& meta) {
  auto& d = *this;
  if (auto e = refuse_meta(meta)) return *e;
  Transaction tx(d.db, d.tx_statements);
  if (auto s = d.begin(tx, "creating a sweep"); !s) return s.error();
  std::int64_t id = 0;
  {
    auto& st = d.insert_sweep;
    Statement::Use use(st);
    bind_sweep(st, meta, d.bench, now_utc());
    const int rc = st.step();
    if (meta.key && (rc == SQLITE_CONSTRAINT_UNIQUE || rc == SQLITE_CONSTRAINT_PRIMARYKEY)) return duplicate_key(*meta.key);
    if (rc != SQLITE_DONE) return d.fail(rc, "creating a sweep");
    id = sqlite3_last_insert_rowid(d.db);
  }
  if (auto s = d.add_event_in_tx(id, EventKind::state, "created", nullptr); !s) return s.error();
  if (auto s = d.commit(tx, "creating a sweep"); !s) return s.error();
  return id;
}

Status SqliteBackend::set_sweep_state(std::int64_t sweep_id, SweepState state, const std::optional<std::string>& error,
                              bool sparse_plan) {
  auto& d = *this;
  const std::string what = "changing the state of sweep " + std::to_string(sweep_id);
  Transaction tx(d.db, d.tx_statements);
  if (auto s = d.begin(tx, what); !s) return s;
  if (auto s = d.change_state_in_tx(sweep_id, state, error, sparse_plan); !s) return s;
  return d.commit(tx, what);
}

Result<std::vector<LeftRunning>> SqliteBackend::abort_left_running() {
  auto& d = *this;
  const std::string what = "marking sweeps left running";
  // One write transaction: a `synbench sweep --resume` cannot take a sweep over between the
  // owner's check and the change.
  Transaction tx(d.db, d.tx_statements);
  if (auto s = d.begin(tx, what); !s) return s.error();
  struct Row {
    std::int64_t id;
    std::optional<std::string> host;
    std::optional<std::int64_t> pid;
    std::optional<std::string> start;
  };
  std::vector<Row> rows;
  {
    auto& st = d.select_running;
    Statement::Use use(st);
    for (;;) {
      const int rc = st.step();
      if (rc == SQLITE_DONE) break;
      if (rc != SQLITE_ROW) return d.fail(rc, what);
      rows.push_back({st.integer(0), st.opt_text(1),
                      st.is_null(2) ? std::nullopt : std::optional<std::int64_t>(st.integer(2)), st.opt_text(3)});
    }
  }
  std::vector<LeftRunning> out;
  for (const auto& r : rows) {
    const std::string owner = describe_owner(r.host, r.pid);
    const std::string sweep = "sweep " + std::to_string(r.id);
    switch (liveness(r.host, r.pid, r.start)) {
      case Liveness::alive:
        out.push_back({r.id, false, sweep + " is running in " + owner + ": left alone"});
        break;
      case Liveness::unknown:
        out.push_back({r.id, false,
                       sweep + " is marked running by " + owner +
                           ", which this process cannot see (another host or container): left alone"});
        break;
      case Liveness::gone: {
        const std::string why = "marked aborted at start: left running by a previous process (" + owner + ")";
        if (auto s = d.change_state_in_tx(r.id, SweepState::aborted, why, false); !s) return s.error();
        out.push_back({r.id, true, sweep + " " + why});
        break;
      }
    }
  }
  if (auto s = d.commit(tx, what); !s) return s.error();
  return out;
}

Result<Sweep> SqliteBackend::get_sweep(std::int64_t sweep_id) {
  auto& d = *this;
  if (auto s = d.check_file(); !s) return s.error();
  auto& st = d.select_sweep;
  Statement::Use use(st);
  st.bind(1, sweep_id);
  const int rc = st.step();
  if (rc == SQLITE_DONE) return make_error(errc::not_found, "no sweep " + std::to_string(sweep_id));
  if (rc != SQLITE_ROW) return d.fail(rc, "reading a sweep");
  return read_sweep(st);
}

Result<std::optional<Sweep>> SqliteBackend::find_sweep_by_key(std::string_view key) {
  auto& d = *this;
  if (auto s = d.check_file(); !s) return s.error();
  auto& st = d.select_sweep_by_key;
  Statement::Use use(st);
  st.bind(1, key);
  const int rc = st.step();
  if (rc == SQLITE_DONE) return std::optional<Sweep>();
  if (rc != SQLITE_ROW) return d.fail(rc, "finding a sweep by key");
  auto s = read_sweep(st);
  if (!s) return s.error();
  return std::optional<Sweep>(std::move(*s));
}

Result<std::vector<Sweep>> SqliteBackend::list_sweeps() {
  auto& d = *this;
  // A read too: what a lost file answers is no longer what is on disk at the path.
  if (auto s = d.check_file(); !s) return s.error();
  auto& st = d.select_sweeps;
  Statement::Use use(st);
  std::vector<Sweep> out;
  for (;;) {
    const int rc = st.step();
    if (rc == SQLITE_DONE) return out;
    if (rc != SQLITE_ROW) return d.fail(rc, "listing sweeps");
    auto s = read_sweep(st);
    if (!s) return s.error();
    out.push_back(std::move(*s));
  }
}

Status SqliteBackend::insert_point(std::int64_t sweep_id, std::int64_t point_index, const bench::PointRecord& record) {
  auto& d = *this;
  const std::string which = "point " + std::to_string(point_index) + " of sweep " + std::to_string(sweep_id);
  Transaction tx(d.db, d.tx_statements);
  if (auto s = d.begin(tx, "storing " + which); !s) return s;
  {
    auto& st = d.sweep_total;
    Statement::Use use(st);
    st.bind(1, sweep_id);
    const int rc = st.step();
    if (rc == SQLITE_DONE) return make_error(errc::not_found, "no sweep " + std::to_string(sweep_id));
    if (rc != SQLITE_ROW) return d.fail(rc, "storing " + which);
    const std::int64_t total = st.integer(0);
    if (point_index < 0 || point_index >= total)
      return make_error(errc::invalid_argument,
                        which + ": the plan has indices 0 to " + std::to_string(total - 1));
  }
  {
    auto& st = d.insert_point_st;
    Statement::Use use(st);
    st.bind(1, sweep_id);
    st.bind(2, point_index);
    bind_record(st, 3, record);
    st.bind(3 + kRecordColumnCount, now_utc());
    const int rc = st.step();
    // The transaction rolls back on the way out; the stored point is untouched.
    if (rc == SQLITE_CONSTRAINT_UNIQUE || rc == SQLITE_CONSTRAINT_PRIMARYKEY)
      return make_error(errc::duplicate_point, which + " is already stored");
    if (rc != SQLITE_DONE) return d.fail(rc, "storing " + which);
  }
  return d.commit(tx, "storing " + which);
}

Result<std::vector<PointRow>> SqliteBackend::points(std::int64_t sweep_id) {
  auto& d = *this;
  if (auto s = d.check_file(); !s) return s.error();
  auto e = d.exists(sweep_id);
  if (!e) return e.error();
  if (!*e) return make_error(errc::not_found, "no sweep " + std::to_string(sweep_id));
  auto& st = d.select_points;
  Statement::Use use(st);
  st.bind(1, sweep_id);
  std::vector<PointRow> out;
  for (;;) {
    const int rc = st.step();
    if (rc == SQLITE_DONE) return out;
    if (rc != SQLITE_ROW) return d.fail(rc, "reading points");
    PointRow row;
    row.index = st.integer(0);
    const auto where = [&] { return "point " + std::to_string(row.index) + " of sweep " + std::to_string(sweep_id); };
    if (auto s = read_record(st, 1, row.record); !s)
      return make_error(errc::bad_record, where() + ": " + s.error().message);
    out.push_back(std::move(row));
  }
}

Result<std::vector<std::int64_t>> SqliteBackend::missing_indices(std::int64_t sweep_id) {
  auto& d = *this;
  if (auto s = d.check_file(); !s) return s.error();
  std::int64_t total = 0;
  {
    auto& st = d.sweep_total;
    Statement::Use use(st);
    st.bind(1, sweep_id);
    const int rc = st.step();
    if (rc == SQLITE_DONE) return make_error(errc::not_found, "no sweep " + std::to_string(sweep_id));
    if (rc != SQLITE_ROW) return d.fail(rc, "reading the sweep's size");
    total = st.integer(0);
  }
  // Stored indices come sorted and lie in 0 .. total-1 (insert_point enforces it): a merge walk.
  auto& st = d.select_indices;
  Statement::Use use(st);
  st.bind(1, sweep_id);
  std::vector<std::int64_t> missing;
  std::int64_t next = 0;
  for (;;) {
    const int rc = st.step();
    if (rc == SQLITE_DONE) break;
    if (rc != SQLITE_ROW) return d.fail(rc, "reading stored indices");
    const std::int64_t stored = st.integer(0);
    for (; next < stored && next < total; ++next) missing.push_back(next);
    next = stored + 1;
  }
  for (; next < total; ++next) missing.push_back(next);
  return missing;
}

Result<std::int64_t> SqliteBackend::add_event(std::optional<std::int64_t> sweep_id, EventKind kind, std::string_view message) {
  auto& d = *this;
  Transaction tx(d.db, d.tx_statements);
  if (auto s = d.begin(tx, "recording an event"); !s) return s.error();
  std::int64_t id = 0;
  if (auto s = d.add_event_in_tx(sweep_id, kind, message, &id); !s) return s.error();
  if (auto s = d.commit(tx, "recording an event"); !s) return s.error();
  return id;
}

Result<std::vector<Event>> SqliteBackend::events(std::optional<std::int64_t> sweep_id) {
  auto& d = *this;
  if (auto s = d.check_file(); !s) return s.error();
  if (sweep_id) {
    auto e = d.exists(*sweep_id);
    if (!e) return e.error();
    if (!*e) return make_error(errc::not_found, "no sweep " + std::to_string(*sweep_id));
  }
  auto& st = sweep_id ? d.select_events_of_sweep : d.select_events_all;
  Statement::Use use(st);
  if (sweep_id) st.bind(1, *sweep_id);
  std::vector<Event> out;
  for (;;) {
    const int rc = st.step();
    if (rc == SQLITE_DONE) return out;
    if (rc != SQLITE_ROW) return d.fail(rc, "reading events");
    auto e = detail::read_event(st);
    if (!e) return e.error();
    out.push_back(std::move(*e));
  }
}

Status SqliteBackend::integrity_check() {
  auto& d = *this;
  std::string findings;
  for (const char* sql : {"PRAGMA integrity_check", "PRAGMA foreign_key_check"}) {
    auto st = Statement::prepare(d.db, sql);
    if (!st) return d.report(st.error());
    for (;;) {
      const int rc = st->step();
      if (rc == SQLITE_DONE) break;
      if (rc != SQLITE_ROW) return d.fail(rc, sql);
      std::string row;
      for (int c = 0; c < sqlite3_column_count(st->get()); ++c) {
        if (c) row += " ";
        row += st->is_null(c) ? "NULL" : st->text(c);
      }
      // integrity_check answers a single "ok" when all is well; foreign_key_check answers nothing.
      if (row == "ok") continue;
      findings += findings.empty() ? "" : "; ";
      findings += row;
    }
  }
  if (findings.empty()) return {};
  return make_error(errc::corrupt, d.path.string() + ": " + findings);
}

Result<std::string> SqliteBackend::pragma(std::string_view pragma_name) {
  auto& d = *this;
  if (pragma_name.empty() || pragma_name.find_first_not_of("abcdefghijklmnopqrstuvwxyz_") != std::string_view::npos)
    return make_error(errc::invalid_argument, "pragma name must be [a-z_]+");
  const std::string sql = "PRAGMA " + std::string(pragma_name);
  auto st = Statement::prepare(d.db, sql);
  if (!st) return st.error();
  const int rc = st->step();
  if (rc == SQLITE_DONE) return std::string();
  if (rc != SQLITE_ROW) return d.fail(rc, sql);
  return st->text(0);
}

}  // namespace synbench::db::detail
