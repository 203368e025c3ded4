// Opening a store: migrations from an empty file, reopening, refusing newer or foreign files,
// one transaction per step, and the connection's pragmas.
#include "db/migrations.hpp"

#include <sqlite3.h>

#include <gtest/gtest.h>

#include <fstream>
#include <set>

#include "bench/point_record_fields.hpp"
#include "db/point_columns.hpp"
#include "db/store.hpp"
#include "tests/db/sample_records.hpp"

namespace synbench::db {
namespace {

using testing::TempDir;

// A plain SQLite connection, to look at the file without the Store.
class Raw {
 public:
  explicit Raw(const std::filesystem::path& p) {
    if (sqlite3_open(p.c_str(), &db_) != SQLITE_OK) throw std::runtime_error("sqlite3_open");
  }
  ~Raw() { sqlite3_close(db_); }
  Raw(const Raw&) = delete;
  Raw& operator=(const Raw&) = delete;
  sqlite3* get() const { return db_; }
  void exec(const std::string& sql) {
    char* err = nullptr;
    if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &err) != SQLITE_OK) {
      std::string m = err ? err : "?";
      sqlite3_free(err);
      throw std::runtime_error(m);
    }
  }
  std::vector<std::string> column(const std::string& sql, int col = 0) {
    sqlite3_stmt* st = nullptr;
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &st, nullptr) != SQLITE_OK) throw std::runtime_error(sqlite3_errmsg(db_));
    std::vector<std::string> out;
    while (sqlite3_step(st) == SQLITE_ROW) {
      const auto* t = sqlite3_column_text(st, col);
      out.emplace_back(t ? reinterpret_cast<const char*>(t) : "NULL");
    }
    sqlite3_finalize(st);
    return out;
  }
  std::string one(const std::string& sql) {
    auto v = column(sql);
    return v.empty() ? "" : v.front();
  }

 private:
  sqlite3* db_ = nullptr;
};

TEST(Migrations, AreNumberedFromOneInOrder) {
  const auto steps = migrations();
  ASSERT_FALSE(steps.empty());
  for (std::size_t i = 0; i < steps.size(); ++i) EXPECT_EQ(steps[i].version, static_cast<int>(i) + 1);
  EXPECT_EQ(schema_version(), steps.back().version);
}

TEST(Migrations, CreateTheSchemaInAnEmptyFile) {
  TempDir dir;
  const auto path = dir / "new.db";
  {
    auto store = Store::open(path);
    ASSERT_TRUE(store) << store.error().message;
    EXPECT_EQ(store->pragma("user_version").value(), std::to_string(schema_version()));
    EXPECT_EQ(store->pragma("application_id").value(), std::to_string(kApplicationId));
  }
  Raw raw(path);
  EXPECT_EQ(raw.column("SELECT name FROM sqlite_schema WHERE type = 'table' ORDER BY name"),
            (std::vector<std::string>{"events", "points", "sweeps"}));
}

TEST(Migrations, ReopeningKeepsDataAndAppliesNothing) {
  TempDir dir;
  const auto path = dir / "reopen.db";
  std::int64_t id = 0;
  {
    auto store = Store::open(path);
    ASSERT_TRUE(store) << store.error().message;
    SweepMeta meta;
    meta.name = "first";
    meta.total_points = 2;
    id = store->create_sweep(meta).value();
    ASSERT_TRUE(store->insert_point(id, 1, testing::sample_record(1)));
  }
  std::string schema_before = Raw(path).one("SELECT group_concat(sql, ';') FROM sqlite_schema");
  auto store = Store::open(path);
  ASSERT_TRUE(store) << store.error().message;
  EXPECT_EQ(store->get_sweep(id).value().meta.name, "first");
  EXPECT_EQ(store->points(id).value().size(), 1u);
  EXPECT_EQ(store->pragma("user_version").value(), std::to_string(schema_version()));
  EXPECT_EQ(Raw(path).one("SELECT group_concat(sql, ';') FROM sqlite_schema"), schema_before);
}

TEST(Migrations, RefuseADatabaseNewerThanTheCode) {
  TempDir dir;
  const auto path = dir / "newer.db";
  { ASSERT_TRUE(Store::open(path)); }
  Raw(path).exec("PRAGMA user_version = " + std::to_string(schema_version() + 1));
  auto store = Store::open(path);
  ASSERT_FALSE(store);
  EXPECT_EQ(store.code(), errc::schema_too_new);
  EXPECT_NE(store.error().message.find("newer"), std::string::npos) << store.error().message;
  EXPECT_NE(store.error().message.find(std::to_string(schema_version() + 1)), std::string::npos);
  // Nothing was touched.
  EXPECT_EQ(Raw(path).one("PRAGMA user_version"), std::to_string(schema_version() + 1));
}

TEST(Migrations, RefuseAnotherApplicationsDatabase) {
  TempDir dir;
  const auto path = dir / "foreign.db";
  Raw(path).exec("CREATE TABLE notes (text TEXT)");
  auto store = Store::open(path);
  ASSERT_FALSE(store);
  EXPECT_EQ(store.code(), errc::not_synbench);
  EXPECT_EQ(Raw(path).column("SELECT name FROM sqlite_schema"), std::vector<std::string>{"notes"});
}

TEST(Migrations, RefuseAFileThatIsNotADatabase) {
  TempDir dir;
  const auto path = dir / "text.db";
  std::ofstream(path) << std::string(4096, 'x');
  auto store = Store::open(path);
  ASSERT_FALSE(store);
  EXPECT_EQ(store.code(), errc::corrupt) << store.error().message;
}

TEST(Migrations, ReportAnUnopenableFile) {
  TempDir dir;
  auto store = Store::open(dir / "no-such-dir" / "x.db");
  ASSERT_FALSE(store);
  EXPECT_EQ(store.code(), errc::io) << store.error().message;
  EXPECT_NE(store.error().message.find("no-such-dir"), std::string::npos);
  EXPECT_EQ(Store::open("").code(), errc::invalid_argument);
}

TEST(Migrations, AVersion1FileGainsTheLaterColumns) {
  // A file as version 1 left it (the columns of steps 2 to 4 dropped again, user_version 1):
  // opening it applies the later steps, and its points read back with the new fields at their
  // defaults.
  TempDir dir;
  const auto path = dir / "v1.db";
  std::int64_t id = 0;
  {
    auto store = Store::open(path);
    ASSERT_TRUE(store) << store.error().message;
    SweepMeta meta;
    meta.name = "v1";
    meta.total_points = 1;
    id = store->create_sweep(meta).value();
    auto r = testing::sample_record(3);
    r.below_min_speed = true;
    r.fallback_fraction = 0.9;
    r.lock_lost = true;
    r.window_source = drivers::WindowKeeper::host;
    r.angle_meas_deg = 61.5;
    r.angle_off = true;
    ASSERT_TRUE(store->insert_point(id, 0, r));
  }
  {
    Raw raw(path);
    raw.exec("DROP INDEX sweeps_by_key");
    raw.exec("ALTER TABLE sweeps DROP COLUMN key");
    raw.exec("ALTER TABLE sweeps DROP COLUMN devices_json");
    raw.exec("ALTER TABLE sweeps DROP COLUMN bench_host");
    raw.exec("ALTER TABLE sweeps DROP COLUMN bench_name");
    raw.exec("ALTER TABLE points DROP COLUMN efficiency_u_repeat");
    raw.exec("ALTER TABLE points DROP COLUMN pdcm_u_repeat_W");
    raw.exec("ALTER TABLE points DROP COLUMN im_u_repeat_A");
    raw.exec("ALTER TABLE points DROP COLUMN efficiency_u");
    raw.exec("ALTER TABLE points DROP COLUMN pm_u_W");
    raw.exec("ALTER TABLE points DROP COLUMN pdcg_u_W");
    raw.exec("ALTER TABLE points DROP COLUMN pdcm_u_W");
    raw.exec("ALTER TABLE points DROP COLUMN im_u_A");
    raw.exec("ALTER TABLE points DROP COLUMN angle_off");
    raw.exec("ALTER TABLE points DROP COLUMN angle_meas_deg");
    raw.exec("ALTER TABLE points DROP COLUMN window_source");
    raw.exec("ALTER TABLE sweeps DROP COLUMN owner_start");
    raw.exec("ALTER TABLE sweeps DROP COLUMN owner_pid");
    raw.exec("ALTER TABLE sweeps DROP COLUMN owner_host");
    raw.exec("ALTER TABLE points DROP COLUMN fault_code_raw");
    raw.exec("ALTER TABLE points DROP COLUMN lock_lost");
    raw.exec("ALTER TABLE points DROP COLUMN fallback_fraction");
    raw.exec("ALTER TABLE points DROP COLUMN below_min_speed");
    raw.exec("PRAGMA user_version = 1");
  }
  auto store = Store::open(path);
  ASSERT_TRUE(store) << store.error().message;
  EXPECT_EQ(store->pragma("user_version").value(), std::to_string(schema_version()));
  const auto rows = store->points(id).value();
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_FALSE(rows[0].record.below_min_speed);
  EXPECT_EQ(rows[0].record.fallback_fraction, 0.0);
  EXPECT_FALSE(rows[0].record.lock_lost);
  EXPECT_EQ(rows[0].record.window_source, drivers::WindowKeeper::device);
  EXPECT_FALSE(rows[0].record.angle_meas_deg) << "not measured before version 7";
  EXPECT_FALSE(rows[0].record.angle_off);
  EXPECT_EQ(rows[0].record.im_A, testing::sample_record(3).im_A);
}

TEST(Migrations, AVersion3FileGainsTheSweepOwner) {
  // Step 4: a sweep a version-3 synbench left running has no owner; opening the file adds the
  // columns (NULL), and the sweep counts as left by a previous process.
  TempDir dir;
  const auto path = dir / "v3.db";
  std::int64_t id = 0;
  {
    auto store = Store::open(path);
    ASSERT_TRUE(store) << store.error().message;
    SweepMeta meta;
    meta.name = "v3";
    meta.total_points = 1;
    id = store->create_sweep(meta).value();
    ASSERT_TRUE(store->set_sweep_state(id, SweepState::running));
  }
  {
    Raw raw(path);
    raw.exec("DROP INDEX sweeps_by_key");
    raw.exec("ALTER TABLE sweeps DROP COLUMN key");
    raw.exec("ALTER TABLE sweeps DROP COLUMN devices_json");
    raw.exec("ALTER TABLE sweeps DROP COLUMN bench_host");
    raw.exec("ALTER TABLE sweeps DROP COLUMN bench_name");
    raw.exec("ALTER TABLE points DROP COLUMN efficiency_u_repeat");
    raw.exec("ALTER TABLE points DROP COLUMN pdcm_u_repeat_W");
    raw.exec("ALTER TABLE points DROP COLUMN im_u_repeat_A");
    raw.exec("ALTER TABLE points DROP COLUMN efficiency_u");
    raw.exec("ALTER TABLE points DROP COLUMN pm_u_W");
    raw.exec("ALTER TABLE points DROP COLUMN pdcg_u_W");
    raw.exec("ALTER TABLE points DROP COLUMN pdcm_u_W");
    raw.exec("ALTER TABLE points DROP COLUMN im_u_A");
    raw.exec("ALTER TABLE points DROP COLUMN angle_off");
    raw.exec("ALTER TABLE points DROP COLUMN angle_meas_deg");
    raw.exec("ALTER TABLE points DROP COLUMN window_source");
    raw.exec("ALTER TABLE sweeps DROP COLUMN owner_start");
    raw.exec("ALTER TABLE sweeps DROP COLUMN owner_pid");
    raw.exec("ALTER TABLE sweeps DROP COLUMN owner_host");
    raw.exec("ALTER TABLE points DROP COLUMN fault_code_raw");
    raw.exec("PRAGMA user_version = 3");
  }
  auto store = Store::open(path);
  ASSERT_TRUE(store) << store.error().message;
  EXPECT_EQ(store->pragma("user_version").value(), std::to_string(schema_version()));
  EXPECT_EQ(Raw(path).column("SELECT coalesce(owner_pid, 'NULL') FROM sweeps"), std::vector<std::string>{"NULL"});
  const auto left = store->abort_left_running().value();
  ASSERT_EQ(left.size(), 1u);
  EXPECT_TRUE(left[0].marked_aborted);
  EXPECT_EQ(store->get_sweep(id).value().state, SweepState::aborted);
}

TEST(Migrations, EachStepIsOneTransaction) {
  // A step that fails halfway leaves the database at the previous version, without the half.
  TempDir dir;
  Raw raw(dir / "steps.db");
  const Migration steps[] = {
      {1, "one table", "CREATE TABLE a (x INTEGER);", ""},
      {2, "fails after its first statement", "CREATE TABLE b (x INTEGER); INSERT INTO nowhere VALUES (1);", ""},
  };
  const auto s = detail::migrate(raw.get(), steps);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message.find("version 2"), std::string::npos) << s.error().message;
  EXPECT_EQ(raw.one("PRAGMA user_version"), "1");
  EXPECT_EQ(raw.column("SELECT name FROM sqlite_schema ORDER BY name"), std::vector<std::string>{"a"});
  // With the step fixed, migration continues from version 1.
  const Migration fixed[] = {steps[0], {2, "fixed", "CREATE TABLE b (x INTEGER);", ""}};
  ASSERT_TRUE(detail::migrate(raw.get(), fixed));
  EXPECT_EQ(raw.one("PRAGMA user_version"), "2");
  EXPECT_EQ(raw.column("SELECT name FROM sqlite_schema ORDER BY name"), (std::vector<std::string>{"a", "b"}));
}

TEST(Pragmas, WalFullSynchronousForeignKeysAndBusyTimeout) {
  TempDir dir;
  const auto path = dir / "pragmas.db";
  StoreOptions options;
  options.busy_timeout_ms = 1234;
  auto store = Store::open(path, options);
  ASSERT_TRUE(store) << store.error().message;
  EXPECT_EQ(store->pragma("journal_mode").value(), "wal");
  EXPECT_EQ(store->pragma("synchronous").value(), "2");  // FULL
  EXPECT_EQ(store->pragma("foreign_keys").value(), "1");
  EXPECT_EQ(store->pragma("busy_timeout").value(), "1234");
  // WAL is a property of the file: another connection sees it too.
  EXPECT_EQ(Raw(path).one("PRAGMA journal_mode"), "wal");
  EXPECT_EQ(store->pragma("not a pragma").code(), errc::invalid_argument);
}

TEST(Schema, PointColumnsAreTheRecordFieldsInOrder) {
  // The record's member table (bench/point_record_fields.hpp), through the store's column names,
  // against the points table that all the migrations together built on a real file.
  std::vector<std::string> fields;
  for (const auto name : bench::field_names(bench::kPointRecordFields)) fields.emplace_back(name);
  std::vector<std::string> columns = detail::record_columns();
  ASSERT_EQ(columns.size(), fields.size());
  EXPECT_EQ(columns.back(), "truth_json") << "a field with a table of its own is one JSON column";
  columns.back() = "truth";
  EXPECT_EQ(columns, fields) << "the other columns carry the fields' names";

  TempDir dir;
  const auto path = dir / "schema.db";
  { ASSERT_TRUE(Store::open(path)); }
  const auto table = Raw(path).column("SELECT name FROM pragma_table_info('points') ORDER BY cid");
  const std::set<std::string> not_record{"id", "sweep_id", "point_index", "measured_at"};
  std::vector<std::string> in_table;
  for (const auto& c : table)
    if (!not_record.contains(c)) in_table.push_back(c);
  // Every field has its column and every column its field ...
  EXPECT_EQ(std::multiset<std::string>(in_table.begin(), in_table.end()),
            std::multiset<std::string>(detail::record_columns().begin(), detail::record_columns().end()));
  // ... in the record's order: ALTER TABLE appends a migration's columns after measured_at, so
  // the table's order is the record's except for version 1's truth_json, which stays in its place.
  std::erase(in_table, "truth_json");
  std::vector<std::string> plain = detail::record_columns();
  std::erase(plain, "truth_json");
  EXPECT_EQ(in_table, plain);
}

}  // namespace
}  // namespace synbench::db
