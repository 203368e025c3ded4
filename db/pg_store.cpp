// The PostgreSQL backend of db::Store: one libpq connection, the schema migrated under an
// advisory lock, one transaction per point (COMMIT returns once the server has the point
// durable: synchronous_commit as the server sets it, `on` by default), SQLSTATEs as db::errc.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "db/backend.hpp"
#include "db/migrations.hpp"
#include "db/owner.hpp"
#include "db/pg.hpp"
#include "db/point_columns.hpp"
#include "db/store.hpp"
#include "db/sweep_rows.hpp"

namespace synbench::db::detail {
namespace {

// The advisory lock key migrations take (the application id, as on SQLite's header): daemons
// starting at once against a fresh database migrate it one after the other.
constexpr std::int64_t kMigrationLock = kApplicationId;

Status migrate_pg(PgConnection& c, std::span<const Migration> steps) {
  const int latest = steps.empty() ? 0 : steps.back().version;
  if (auto r = c.exec("SELECT pg_advisory_lock(" + std::to_string(kMigrationLock) + ")", "locking for migration"); !r)
    return r.error();
  struct Unlock {
    PgConnection& c;
    ~Unlock() { (void)c.exec("SELECT pg_advisory_unlock(" + std::to_string(kMigrationLock) + ")", "unlocking"); }
  } unlock{c};
  for (;;) {
    // synbench_schema marks the database as synbench's (application_id, as SQLite's header
    // does) and holds its version. Without it, the database is ours to initialise only if its
    // schema holds no tables.
    auto has = c.exec("SELECT to_regclass('synbench_schema') IS NOT NULL, "
                      "(SELECT count(*) FROM pg_tables WHERE schemaname = current_schema())",
                      "reading the schema version");
    if (!has) return has.error();
    const PgRow h(has->get(), 0);
    int version = 0;
    if (h.text(0) == "t") {
      auto v = c.exec("SELECT application_id, version FROM synbench_schema", "reading the schema version");
      if (!v) return v.error();
      if (PQntuples(v->get()) != 1) return make_error(errc::not_synbench, c.shown() + ": synbench_schema is not one row");
      const PgRow row(v->get(), 0);
      if (row.integer(0) != kApplicationId)
        return make_error(errc::not_synbench, c.shown() + ": synbench_schema names application " + row.text(0));
      version = static_cast<int>(row.integer(1));
    } else if (h.integer(1) != 0) {
      return make_error(errc::not_synbench, c.shown() + ": the database holds " + h.text(1) +
                                                " tables of another application (no synbench_schema)");
    }
    if (version > latest)
      return make_error(errc::schema_too_new, c.shown() + ": database schema version " + std::to_string(version) +
                                                  " is newer than this synbench understands (up to " +
                                                  std::to_string(latest) + "); use a newer synbench to open it");
    if (version == latest) return {};
    const Migration& step = steps[static_cast<std::size_t>(version)];
    const std::string where = "migration to schema version " + std::to_string(step.version);
    PgTransaction tx(c);
    if (auto s = tx.begin(where); !s) return s;
    if (version == 0) {
      const std::string mark = "CREATE TABLE synbench_schema (application_id integer NOT NULL, version integer NOT NULL);"
                               "INSERT INTO synbench_schema VALUES (" + std::to_string(kApplicationId) + ", 0);";
      if (auto s = c.exec_script(mark, where); !s) return s;
    }
    if (auto s = c.exec_script(step.pg_sql, where); !s) return s;
    if (auto r = c.exec("UPDATE synbench_schema SET version = " + std::to_string(step.version), where); !r)
      return r.error();
    if (auto s = tx.commit(where); !s) return s;
  }
}

class PgBackend final : public Backend {
 public:
  explicit PgBackend(PgConnection c) : c_(std::move(c)) {}

  Status setup(const StoreOptions& options) {
    if (options.max_page_count)
      return make_error(errc::unsupported, c_.shown() + ": max_page_count is SQLite's; PostgreSQL's size limits are "
                                                        "the server's (tablespace quotas, disk)");
    if (auto s = c_.set_session("SET lock_timeout = " + std::to_string(options.busy_timeout_ms), "setting lock_timeout"); !s)
      return s;
    if (auto s = migrate_pg(c_, migrations()); !s) return s;
    if (options.verify) {
      // A committed write, as on SQLite: a read-only role or a standby is refused here.
      PgTransaction tx(c_);
      if (auto s = tx.begin("writing"); !s) return s;
      if (auto r = c_.exec("UPDATE synbench_schema SET version = version", "writing"); !r) return r.error();
      if (auto s = tx.commit("writing"); !s) return s;
    }
    on_error_ = options.on_error;
    bench_ = resolved(options.bench);
    return {};
  }

  Result<std::int64_t> create_sweep(const SweepMeta& meta) override {
    if (auto e = refuse_meta(meta)) return *e;
    PgTransaction tx(c_);
    if (auto s = tx.begin("creating a sweep"); !s) return fail(s.error());
    PgParams p;
    bind_sweep(p, meta, bench_, now_utc());
    auto r = c_.exec(pg_sql(kInsertSweepSql) + " RETURNING id", p, "creating a sweep");
    if (!r) {
      if (meta.key && r.code() == errc::duplicate_point) return duplicate_key(*meta.key);
      return fail(r.error());
    }
    const std::int64_t id = PgRow(r->get(), 0).integer(0);
    if (auto s = add_event_in_tx(id, EventKind::state, "created", nullptr); !s) return s.error();
    if (auto s = tx.commit("creating a sweep"); !s) return fail(s.error());
    return id;
  }

  Result<std::optional<Sweep>> find_sweep_by_key(std::string_view key) override {
    PgParams p;
    p.bind(1, key);
    auto r = c_.exec(pg_sql(std::string(kSweepColumns) + " WHERE s.key = ?"), p, "finding a sweep by key");
    if (!r) return fail(r.error());
    if (PQntuples(r->get()) == 0) return std::optional<Sweep>();
    auto s = read_sweep(PgRow(r->get(), 0));
    if (!s) return s.error();
    return std::optional<Sweep>(std::move(*s));
  }

  Status set_sweep_state(std::int64_t sweep_id, SweepState state, const std::optional<std::string>& error,
                         bool sparse_plan) override {
    const std::string what = "changing the state of sweep " + std::to_string(sweep_id);
    PgTransaction tx(c_);
    if (auto s = tx.begin(what); !s) return fail(s.error());
    if (auto s = change_state_in_tx(sweep_id, state, error, sparse_plan); !s) return s;
    if (auto s = tx.commit(what); !s) return fail(s.error());
    return {};
  }

  Result<Sweep> get_sweep(std::int64_t sweep_id) override {
    PgParams p;
    p.bind(1, sweep_id);
    auto r = c_.exec(pg_sql(std::string(kSweepColumns) + " WHERE s.id = ?"), p, "reading a sweep");
    if (!r) return fail(r.error());
    if (PQntuples(r->get()) == 0) return make_error(errc::not_found, "no sweep " + std::to_string(sweep_id));
    return read_sweep(PgRow(r->get(), 0));
  }

  Result<std::vector<Sweep>> list_sweeps() override {
    auto r = c_.exec(std::string(kSweepColumns) + " ORDER BY s.id", "listing sweeps");
    if (!r) return fail(r.error());
    std::vector<Sweep> out;
    for (int i = 0; i < PQntuples(r->get()); ++i) {
      auto s = read_sweep(PgRow(r->get(), i));
      if (!s) return s.error();
      out.push_back(std::move(*s));
    }
    return out;
  }

  Result<std::vector<LeftRunning>> abort_left_running() override {
    const std::string what = "marking sweeps left running";
    PgTransaction tx(c_);
    if (auto s = tx.begin(what); !s) return fail(s.error());
    // FOR UPDATE: a `synbench sweep --resume` on another host cannot take a sweep over between
    // the owner's check and the change.
    auto r = c_.exec("SELECT id, owner_host, owner_pid, owner_start FROM sweeps WHERE state = 'running' "
                     "ORDER BY id FOR UPDATE",
                     what);
    if (!r) return fail(r.error());
    std::vector<LeftRunning> out;
    for (int i = 0; i < PQntuples(r->get()); ++i) {
      const PgRow row(r->get(), i);
      const std::int64_t id = row.integer(0);
      const auto host = row.opt_text(1);
      const auto pid = row.is_null(2) ? std::nullopt : std::optional<std::int64_t>(row.integer(2));
      const std::string owner = describe_owner(host, pid);
      const std::string sweep = "sweep " + std::to_string(id);
      switch (liveness(host, pid, row.opt_text(3))) {
        case Liveness::alive:
          out.push_back({id, false, sweep + " is running in " + owner + ": left alone"});
          break;
        case Liveness::unknown:
          out.push_back({id, false,
                         sweep + " is marked running by " + owner +
                             ", which this process cannot see (another host or container): left alone"});
          break;
        case Liveness::gone: {
          const std::string why = "marked aborted at start: left running by a previous process (" + owner + ")";
          if (auto s = change_state_in_tx(id, SweepState::aborted, why, false); !s) return s.error();
          out.push_back({id, true, sweep + " " + why});
          break;
        }
      }
    }
    if (auto s = tx.commit(what); !s) return fail(s.error());
    return out;
  }

  Status insert_point(std::int64_t sweep_id, std::int64_t point_index, const bench::PointRecord& record) override {
    const std::string which = "point " + std::to_string(point_index) + " of sweep " + std::to_string(sweep_id);
    const std::string what = "storing " + which;
    PgTransaction tx(c_);
    if (auto s = tx.begin(what); !s) return fail(s.error());
    {
      PgParams p;
      p.bind(1, sweep_id);
      auto r = c_.exec("SELECT total_points FROM sweeps WHERE id = $1", p, what);
      if (!r) return fail(r.error());
      if (PQntuples(r->get()) == 0) return make_error(errc::not_found, "no sweep " + std::to_string(sweep_id));
      const std::int64_t total = PgRow(r->get(), 0).integer(0);
      if (point_index < 0 || point_index >= total)
        return make_error(errc::invalid_argument, which + ": the plan has indices 0 to " + std::to_string(total - 1));
    }
    {
      PgParams p;
      p.bind(1, sweep_id);
      p.bind(2, point_index);
      bind_record(p, 3, record);
      p.bind(3 + kRecordColumnCount, now_utc());
      auto r = c_.exec(insert_point_sql_, p, what);
      if (!r) {
        // UNIQUE (sweep_id, point_index): the transaction rolls back, the stored point stays.
        if (r.code() == errc::duplicate_point) return make_error(errc::duplicate_point, which + " is already stored");
        if (r.code() == errc::not_found) return make_error(errc::not_found, "no sweep " + std::to_string(sweep_id));
        return fail(r.error());
      }
    }
    if (auto s = tx.commit(what); !s) return fail(s.error());
    return {};
  }

  Result<std::vector<PointRow>> points(std::int64_t sweep_id) override {
    if (auto e = exists(sweep_id); !e) return e.error();
    PgParams p;
    p.bind(1, sweep_id);
    auto r = c_.exec(select_points_sql_, p, "reading points");
    if (!r) return fail(r.error());
    std::vector<PointRow> out;
    for (int i = 0; i < PQntuples(r->get()); ++i) {
      const PgRow row(r->get(), i);
      PointRow pr;
      pr.index = row.integer(0);
      if (auto s = read_record(row, 1, pr.record); !s)
        return make_error(errc::bad_record, "point " + std::to_string(pr.index) + " of sweep " +
                                                std::to_string(sweep_id) + ": " + s.error().message);
      out.push_back(std::move(pr));
    }
    return out;
  }

  Result<std::vector<std::int64_t>> missing_indices(std::int64_t sweep_id) override {
    PgParams p;
    p.bind(1, sweep_id);
    auto t = c_.exec("SELECT total_points FROM sweeps WHERE id = $1", p, "reading the sweep's size");
    if (!t) return fail(t.error());
    if (PQntuples(t->get()) == 0) return make_error(errc::not_found, "no sweep " + std::to_string(sweep_id));
    const std::int64_t total = PgRow(t->get(), 0).integer(0);
    auto r = c_.exec("SELECT point_index FROM points WHERE sweep_id = $1 ORDER BY point_index", p,
                     "reading stored indices");
    if (!r) return fail(r.error());
    std::vector<std::int64_t> stored;
    for (int i = 0; i < PQntuples(r->get()); ++i) stored.push_back(PgRow(r->get(), i).integer(0));
    return missing_from(total, stored);
  }

  Result<std::int64_t> add_event(std::optional<std::int64_t> sweep_id, EventKind kind,
                                 std::string_view message) override {
    // One statement is its own transaction.
    std::int64_t id = 0;
    if (auto s = add_event_in_tx(sweep_id, kind, message, &id); !s) return s.error();
    return id;
  }

  Result<std::vector<Event>> events(std::optional<std::int64_t> sweep_id) override {
    PgParams p;
    if (sweep_id) {
      if (auto e = exists(*sweep_id); !e) return e.error();
      p.bind(1, *sweep_id);
    }
    const std::string columns(detail::kEventColumns);
    auto r = sweep_id ? c_.exec(columns + " WHERE sweep_id = $1 ORDER BY id", p, "reading events")
                      : c_.exec(columns + " ORDER BY id", "reading events");
    if (!r) return fail(r.error());
    std::vector<Event> out;
    for (int i = 0; i < PQntuples(r->get()); ++i) {
      auto e = detail::read_event(PgRow(r->get(), i));
      if (!e) return e.error();
      out.push_back(std::move(*e));
    }
    return out;
  }

  // PostgreSQL checks its constraints on every write and its pages on read (checksums when
  // initdb enabled them); what is left to look at is rows a bug could leave behind.
  Status integrity_check() override {
    auto r = c_.exec("SELECT (SELECT count(*) FROM points p WHERE NOT EXISTS (SELECT 1 FROM sweeps s WHERE s.id = p.sweep_id)), "
                     "(SELECT count(*) FROM sweeps WHERE state NOT IN ('created','running','paused','completed','aborted','faulted'))",
                     "checking integrity");
    if (!r) return fail(r.error());
    const PgRow row(r->get(), 0);
    if (row.integer(0) != 0 || row.integer(1) != 0)
      return make_error(errc::corrupt, c_.shown() + ": " + row.text(0) + " orphan points, " + row.text(1) +
                                           " sweeps in an unknown state");
    return {};
  }

  Result<std::string> pragma(std::string_view name) override {
    return make_error(errc::unsupported, c_.shown() + ": PRAGMA " + std::string(name) +
                                             " is SQLite's; a PostgreSQL store has no pragmas");
  }

 private:
  Error fail(Error e) const {
    if (on_error_ && is_storage_failure(e.code)) on_error_(e);
    return e;
  }

  Result<bool> exists(std::int64_t sweep_id) {
    PgParams p;
    p.bind(1, sweep_id);
    auto r = c_.exec("SELECT 1 FROM sweeps WHERE id = $1", p, "looking up the sweep");
    if (!r) return fail(r.error());
    if (PQntuples(r->get()) == 0) return make_error(errc::not_found, "no sweep " + std::to_string(sweep_id));
    return true;
  }

  Status add_event_in_tx(std::optional<std::int64_t> sweep_id, EventKind kind, std::string_view message,
                         std::int64_t* id) {
    PgParams p;
    p.bind(1, sweep_id);
    p.bind(2, now_utc());
    p.bind(3, name(kind));
    p.bind(4, message);
    auto r = c_.exec("INSERT INTO events (sweep_id, at, kind, message) VALUES ($1, $2, $3, $4) RETURNING id", p,
                     "recording an event");
    if (!r) {
      if (r.code() == errc::not_found) return make_error(errc::not_found, "no sweep " + std::to_string(sweep_id.value_or(0)));
      return fail(r.error());
    }
    if (id) *id = PgRow(r->get(), 0).integer(0);
    return {};
  }

  Status change_state_in_tx(std::int64_t sweep_id, SweepState state, const std::optional<std::string>& error,
                            bool sparse_plan) {
    PgParams p;
    p.bind(1, sweep_id);
    // FOR UPDATE: two processes changing one sweep's state take turns.
    auto r = c_.exec("SELECT state, started_at, total_points, (SELECT count(*) FROM points WHERE sweep_id = $1) "
                     "FROM sweeps WHERE id = $1 FOR UPDATE",
                     p, "reading the sweep's state");
    if (!r) return fail(r.error());
    if (PQntuples(r->get()) == 0) return make_error(errc::not_found, "no sweep " + std::to_string(sweep_id));
    const PgRow row(r->get(), 0);
    const auto from = parse_sweep_state(row.text(0));
    if (!from) return make_error(errc::bad_record, "sweep " + std::to_string(sweep_id) + " has an unknown state");
    auto started_at = row.opt_text(1);
    if (auto refused = refuse_transition(*from, state, row.integer(3), row.integer(2), sparse_plan)) return *refused;
    const std::string now = now_utc();
    if (state == SweepState::running && !started_at) started_at = now;
    const bool running = state == SweepState::running;
    PgParams u;
    u.bind(1, name(state));
    u.bind(2, started_at);
    u.bind(3, finished(state) ? std::optional<std::string>(now) : std::nullopt);
    u.bind(4, error);
    u.bind(5, running ? std::optional<std::string>(me_.host) : std::nullopt);
    u.bind(6, running ? std::optional<std::int64_t>(me_.pid) : std::nullopt);
    u.bind(7, running && !me_.start.empty() ? std::optional<std::string>(me_.start) : std::nullopt);
    u.bind(8, sweep_id);
    if (auto w = c_.exec(pg_sql(kUpdateSweepStateSql), u, "changing the sweep's state"); !w) return fail(w.error());
    const std::string transition = std::string(name(*from)) + " -> " + std::string(name(state));
    return add_event_in_tx(sweep_id, EventKind::state, error ? transition + ": " + *error : transition, nullptr);
  }

  PgConnection c_;
  ProcessOwner me_ = this_process();
  BenchIdentity bench_;
  std::function<void(const Error&)> on_error_;
  const std::string insert_point_sql_ = pg_sql(insert_point_sql());
  const std::string select_points_sql_ = pg_sql(select_points_sql());
};

}  // namespace

Result<std::unique_ptr<Backend>> open_postgres(const std::string& conninfo, const std::string& shown,
                                               const StoreOptions& options) {
  auto c = PgConnection::connect(conninfo, shown);
  if (!c) return c.error();
  auto b = std::make_unique<PgBackend>(std::move(*c));
  if (auto s = b->setup(options); !s) return s.error();
  return std::unique_ptr<Backend>(std::move(b));
}

}  // namespace synbench::db::detail
