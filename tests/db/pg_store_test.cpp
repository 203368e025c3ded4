// The PostgreSQL backend's own promises, on the test cluster: its schema (the same steps as
// SQLite's, tracked in synbench_schema), migration by several processes at once, refusals of a
// foreign or newer database, keys, a lost connection, errors with SQLSTATE and no password.
#include <gtest/gtest.h>

#include <set>
#include <thread>

#include "bench/point_record_fields.hpp"
#include "db/migrations.hpp"
#include "db/point_columns.hpp"
#include "db/store.hpp"
#include "tests/db/pg_cluster.hpp"
#include "tests/db/sample_records.hpp"

namespace synbench::db {
namespace {

using testing::PgCluster;

SweepMeta meta(const std::string& name, std::int64_t total) {
  SweepMeta m;
  m.name = name;
  m.total_points = total;
  return m;
}

class PgStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    cluster_ = PgCluster::shared();
    ASSERT_NE(cluster_, nullptr) << PgCluster::error();
    db_ = cluster_->create_database();
  }
  Store open(const StoreOptions& options = {}) {
    auto s = Store::open(cluster_->url(db_), options);
    if (!s) throw std::runtime_error(s.error().message);
    return std::move(*s);
  }
  std::string sql(const std::string& q) { return cluster_->psql(db_, q); }

  PgCluster* cluster_ = nullptr;
  std::string db_;
};

TEST(PgSchema, EveryStepHasBothDialectsAndTheListEndsAtTheSchemaVersion) {
  const auto steps = migrations();
  ASSERT_FALSE(steps.empty());
  for (const auto& m : steps) {
    EXPECT_FALSE(m.sql.empty()) << "step " << m.version << " has no SQLite SQL";
    EXPECT_FALSE(m.pg_sql.empty()) << "step " << m.version << " has no PostgreSQL SQL";
  }
  EXPECT_EQ(steps.back().version, schema_version());
}

TEST_F(PgStoreTest, ANewDatabaseIsMarkedOursAtTheCurrentVersionWithTheRecordsColumnsInOrder) {
  { Store s = open(); EXPECT_EQ(s.kind(), Store::Kind::postgres); }
  EXPECT_EQ(sql("SELECT application_id || ' ' || version FROM synbench_schema"),
            std::to_string(kApplicationId) + " " + std::to_string(schema_version()));
  // The points table as all steps built it: the record's columns (lower case: unquoted names
  // fold), in the record's order as on SQLite (truth_json stays in version 1's place).
  const std::string cols =
      sql("SELECT string_agg(column_name, ',' ORDER BY ordinal_position) FROM information_schema.columns "
          "WHERE table_name = 'points' AND column_name NOT IN ('id','sweep_id','point_index','measured_at','truth_json')");
  std::string want;
  for (const auto& c : detail::record_columns()) {
    if (c == "truth_json") continue;
    std::string lower;
    for (const char ch : c) lower += static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    want += (want.empty() ? "" : ",") + lower;
  }
  EXPECT_EQ(cols, want);
  // Reopening changes nothing.
  { Store s = open(); }
  EXPECT_EQ(sql("SELECT count(*) FROM synbench_schema"), "1");
}

TEST_F(PgStoreTest, SeveralProcessesMigratingAFreshDatabaseAtOnceTakeTurns) {
  std::vector<std::thread> threads;
  std::vector<std::string> errors(6);
  for (std::size_t i = 0; i < errors.size(); ++i)
    threads.emplace_back([&, i] {
      auto s = Store::open(cluster_->url(db_));
      if (!s) errors[i] = s.error().message;
    });
  for (auto& t : threads) t.join();
  for (const auto& e : errors) EXPECT_EQ(e, "");
  EXPECT_EQ(sql("SELECT version FROM synbench_schema"), std::to_string(schema_version()));
}

TEST_F(PgStoreTest, AnotherApplicationsOrANewerDatabaseIsRefusedUntouched) {
  sql("CREATE TABLE notes (text text)");
  auto foreign = Store::open(cluster_->url(db_));
  ASSERT_FALSE(foreign);
  EXPECT_EQ(foreign.code(), errc::not_synbench) << foreign.error().message;
  EXPECT_EQ(sql("SELECT count(*) FROM pg_tables WHERE schemaname = 'public'"), "1");

  const std::string other = cluster_->create_database();
  { ASSERT_TRUE(Store::open(cluster_->url(other))); }
  cluster_->psql(other, "UPDATE synbench_schema SET version = version + 1");
  auto newer = Store::open(cluster_->url(other));
  ASSERT_FALSE(newer);
  EXPECT_EQ(newer.code(), errc::schema_too_new);
  EXPECT_NE(newer.error().message.find(std::to_string(schema_version() + 1)), std::string::npos);
}

TEST_F(PgStoreTest, TheUnixSocketFormAndTheUrlReachTheSameDatabase) {
  Store a = open();
  const auto id = a.create_sweep(meta("s", 1)).value();
  ASSERT_TRUE(a.insert_point(id, 0, testing::sample_record(4)));
  auto b = Store::open(cluster_->socket_target(db_));
  ASSERT_TRUE(b) << b.error().message;
  EXPECT_EQ(b->kind(), Store::Kind::postgres);
  EXPECT_EQ(testing::exact_text(b->points(id).value().at(0).record), testing::exact_text(testing::sample_record(4)));
}

TEST_F(PgStoreTest, KeysAreUniqueAndFoundAgain) {
  Store s = open();
  SweepMeta m = meta("shard", 3);
  m.key = "study/0/1";
  const auto id = s.create_sweep(m).value();
  EXPECT_EQ(s.find_sweep_by_key("study/0/1").value()->id, id);
  EXPECT_FALSE(s.find_sweep_by_key("study/0/2").value());
  EXPECT_EQ(s.create_sweep(m).code(), errc::duplicate_key);
  EXPECT_EQ(s.list_sweeps().value().size(), 1u);
  ASSERT_TRUE(s.create_sweep(meta("a", 1)));
  ASSERT_TRUE(s.create_sweep(meta("b", 1)));
}

TEST_F(PgStoreTest, SqliteOnlyFeaturesAreRefusedClearly) {
  Store s = open();
  EXPECT_EQ(s.pragma("journal_mode").code(), errc::unsupported);
  StoreOptions o;
  o.max_page_count = 10;
  auto limited = Store::open(cluster_->url(db_), o);
  ASSERT_FALSE(limited);
  EXPECT_EQ(limited.code(), errc::unsupported);
  EXPECT_NE(limited.error().message.find("max_page_count"), std::string::npos);
  EXPECT_TRUE(s.integrity_check());
}

TEST_F(PgStoreTest, ErrorsCarryLibpqsTextAndSqlstateButNeverThePassword) {
  const std::string target = "postgresql://synbench:s3cret-pw@127.0.0.1:" + std::to_string(cluster_->port()) + "/no_such_db";
  auto s = Store::open(target);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.code(), errc::connection_lost);
  EXPECT_NE(s.error().message.find("no_such_db"), std::string::npos) << s.error().message;
  EXPECT_EQ(s.error().message.find("s3cret-pw"), std::string::npos) << s.error().message;
  EXPECT_EQ(shown_target(target), "postgresql://synbench:***@127.0.0.1:" + std::to_string(cluster_->port()) + "/no_such_db");
  EXPECT_EQ(shown_target("host=/tmp/x password='a b' dbname=d"), "host=/tmp/x password=*** dbname=d");
  EXPECT_EQ(shown_target("postgresql:///d?host=/tmp/x&password=zz&port=5"), "postgresql:///d?host=/tmp/x&password=***&port=5");
  EXPECT_EQ(shown_target("data/synbench.db"), "data/synbench.db");
  EXPECT_FALSE(is_postgres_target("data/synbench.db"));
  EXPECT_TRUE(is_postgres_target("host=/run/pg dbname=lab"));

  // A statement the server refuses: its SQLSTATE in the message, the code translated.
  Store ok = open();
  const auto id = ok.create_sweep(meta("s", 2)).value();
  ASSERT_TRUE(ok.insert_point(id, 0, testing::sample_record(0)));
  const auto dup = ok.insert_point(id, 0, testing::sample_record(1));
  EXPECT_EQ(dup.code(), errc::duplicate_point);
  const auto bad = ok.add_event(999, EventKind::log, "x");
  EXPECT_EQ(bad.code(), errc::not_found);
  // A refusal the store has no word for keeps the server's own text and its SQLSTATE.
  sql("ALTER TABLE points ADD CONSTRAINT only_index_0 CHECK (point_index < 1)");
  const auto refused = ok.insert_point(id, 1, testing::sample_record(1));
  EXPECT_EQ(refused.code(), errc::invalid_argument);
  EXPECT_NE(refused.error().message.find("only_index_0"), std::string::npos) << refused.error().message;
  EXPECT_NE(refused.error().message.find("(SQLSTATE 23514)"), std::string::npos) << refused.error().message;
  EXPECT_NE(refused.error().message.find("storing point 1 of sweep"), std::string::npos) << refused.error().message;
}

TEST_F(PgStoreTest, ALostConnectionIsReportedAndTheNextCallReconnects) {
  Store s = open();
  const auto id = s.create_sweep(meta("s", 3)).value();
  ASSERT_TRUE(s.insert_point(id, 0, testing::sample_record(0)));
  sql("SELECT pg_terminate_backend(pid) FROM pg_stat_activity WHERE datname = current_database() AND pid <> pg_backend_pid()");
  const auto lost = s.insert_point(id, 1, testing::sample_record(1));
  ASSERT_FALSE(lost);
  EXPECT_EQ(lost.code(), errc::connection_lost) << lost.error().message;
  // Nothing half-stored; the next call reconnects and resumes at the first missing index.
  EXPECT_EQ(s.first_missing_index(id).value(), 1);
  ASSERT_TRUE(s.insert_point(id, 1, testing::sample_record(1)));
  EXPECT_EQ(s.missing_indices(id).value(), std::vector<std::int64_t>{2});
}

TEST_F(PgStoreTest, ASweepLeftRunningOnAnotherHostIsLeftAloneOneOnThisHostWithItsProcessGoneIsAborted) {
  Store s = open();
  const auto here = s.create_sweep(meta("here", 1)).value();
  const auto there = s.create_sweep(meta("there", 1)).value();
  ASSERT_TRUE(s.set_sweep_state(here, SweepState::running));
  ASSERT_TRUE(s.set_sweep_state(there, SweepState::running));
  // "here": this host, a pid that is not running; "there": another bench's host.
  sql("UPDATE sweeps SET owner_pid = 2147483646, owner_start = NULL WHERE id = " + std::to_string(here));
  sql("UPDATE sweeps SET owner_host = 'bench-pc-7', owner_pid = 42 WHERE id = " + std::to_string(there));
  const auto left = s.abort_left_running().value();
  ASSERT_EQ(left.size(), 2u);
  EXPECT_TRUE(left[0].marked_aborted) << left[0].message;
  EXPECT_FALSE(left[1].marked_aborted);
  EXPECT_NE(left[1].message.find("pid 42 on bench-pc-7"), std::string::npos) << left[1].message;
  EXPECT_EQ(s.get_sweep(here).value().state, SweepState::aborted);
  EXPECT_EQ(s.get_sweep(there).value().state, SweepState::running);
}

}  // namespace
}  // namespace synbench::db
