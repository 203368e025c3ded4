// The store on both backends, a real SQLite file and a real PostgreSQL database (the test
// cluster, tests/db/pg_cluster.hpp): sweeps and their states, every record field through the
// database, duplicates, missing indices, events, integrity.
#include "db/store.hpp"

#include <sqlite3.h>

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>
#include <regex>
#include <set>

#include "bench/point_record_fields.hpp"

#include "tests/db/pg_cluster.hpp"
#include "tests/db/sample_records.hpp"

namespace synbench::db {
namespace {

using testing::exact_text;
using testing::sample_record;
using testing::TempDir;

class StoreTest : public ::testing::TestWithParam<Store::Kind> {
 protected:
  void SetUp() override {
    if (GetParam() == Store::Kind::sqlite) {
      target_ = (dir_ / "store.db").string();
    } else {
      auto* cluster = testing::PgCluster::shared();
      ASSERT_NE(cluster, nullptr) << testing::PgCluster::error();
      target_ = cluster->url(cluster->create_database());
    }
    auto s = Store::open(target_);
    ASSERT_TRUE(s) << s.error().message;
    ASSERT_EQ(s->kind(), GetParam());
    store_.emplace(std::move(*s));
  }

  std::int64_t make_sweep(std::int64_t total, const std::string& name = "sweep") {
    SweepMeta meta;
    meta.name = name;
    meta.total_points = total;
    auto id = store_->create_sweep(meta);
    EXPECT_TRUE(id) << id.error().message;
    return id ? *id : -1;
  }

  TempDir dir_;
  std::string target_;
  std::optional<Store> store_;
};

std::string kind_name(const ::testing::TestParamInfo<Store::Kind>& i) {
  return i.param == Store::Kind::sqlite ? "sqlite" : "postgres";
}
INSTANTIATE_TEST_SUITE_P(Backends, StoreTest, ::testing::Values(Store::Kind::sqlite, Store::Kind::postgres), kind_name);

// What only a SQLite file can be asked: rows written behind the store's back with SQLite's
// JSON functions.
class SqliteStoreTest : public StoreTest {};
INSTANTIATE_TEST_SUITE_P(Backends, SqliteStoreTest, ::testing::Values(Store::Kind::sqlite), kind_name);

TEST_P(StoreTest, CreatesASweepWithItsMetadata) {
  SweepMeta meta;
  meta.name = "thesis grid, encoder";
  meta.plan = synbench::Json::parse(R"({"speeds_rpm":[500,1000],"loads_Nm":[0,1.5],"z":1,"a":2})");
  meta.profiles = {{"synrm", {{"unit", 1}}}, {"pmsm", {{"unit", 2}}}};
  meta.bench_config = {{"transport", "twin"}};
  meta.total_points = 4;  // calibration left null
  const auto id = store_->create_sweep(meta);
  ASSERT_TRUE(id) << id.error().message;

  const auto s = store_->get_sweep(*id);
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_EQ(s->id, *id);
  EXPECT_EQ(s->meta.name, meta.name);
  EXPECT_EQ(s->meta.plan.dump(), meta.plan.dump()) << "key order kept";
  EXPECT_EQ(s->meta.profiles, meta.profiles);
  EXPECT_EQ(s->meta.bench_config, meta.bench_config);
  EXPECT_TRUE(s->meta.calibration.is_null());
  EXPECT_EQ(s->meta.software_version, std::string(kVersion));
  EXPECT_EQ(s->meta.total_points, 4);
  EXPECT_EQ(s->state, SweepState::created);
  EXPECT_TRUE(std::regex_match(s->created_at, std::regex(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z)")))
      << s->created_at;
  EXPECT_FALSE(s->started_at);
  EXPECT_FALSE(s->finished_at);
  EXPECT_FALSE(s->last_error);
  EXPECT_EQ(s->points_stored, 0);
}

TEST_P(StoreTest, RefusesBadSweepMetadata) {
  SweepMeta meta;
  EXPECT_EQ(store_->create_sweep(meta).code(), errc::invalid_argument) << "no name";
  meta.name = "x";
  meta.total_points = -1;
  EXPECT_EQ(store_->create_sweep(meta).code(), errc::invalid_argument);
  EXPECT_TRUE(store_->list_sweeps().value().empty());
}

TEST_P(StoreTest, ListsSweepsById) {
  const auto a = make_sweep(1, "a");
  const auto b = make_sweep(2, "b");
  const auto list = store_->list_sweeps();
  ASSERT_TRUE(list);
  ASSERT_EQ(list->size(), 2u);
  EXPECT_EQ((*list)[0].id, a);
  EXPECT_EQ((*list)[0].meta.name, "a");
  EXPECT_EQ((*list)[1].id, b);
  EXPECT_EQ((*list)[1].meta.total_points, 2);
}

TEST_P(StoreTest, StateChangesStampTimesAndRecordEvents) {
  const auto id = make_sweep(2);
  ASSERT_TRUE(store_->set_sweep_state(id, SweepState::running));
  const auto started = store_->get_sweep(id).value().started_at;
  ASSERT_TRUE(started);
  ASSERT_TRUE(store_->set_sweep_state(id, SweepState::paused));
  ASSERT_TRUE(store_->set_sweep_state(id, SweepState::running));
  EXPECT_EQ(store_->get_sweep(id).value().started_at, started) << "first start kept";
  ASSERT_TRUE(store_->set_sweep_state(id, SweepState::faulted, std::string("overcurrent at point 1")));
  auto s = store_->get_sweep(id).value();
  EXPECT_EQ(s.state, SweepState::faulted);
  EXPECT_TRUE(s.finished_at);
  EXPECT_EQ(s.last_error, "overcurrent at point 1");
  // Resumed after the fault: unfinished again, the error kept for the record.
  ASSERT_TRUE(store_->set_sweep_state(id, SweepState::running));
  s = store_->get_sweep(id).value();
  EXPECT_FALSE(s.finished_at);
  EXPECT_EQ(s.last_error, "overcurrent at point 1");

  const auto ev = store_->events(id).value();
  std::vector<std::string> messages;
  for (const auto& e : ev) {
    EXPECT_EQ(e.kind, EventKind::state);
    EXPECT_EQ(e.sweep_id, id);
    messages.push_back(e.message);
  }
  EXPECT_EQ(messages, (std::vector<std::string>{"created", "created -> running", "running -> paused",
                                                "paused -> running",
                                                "running -> faulted: overcurrent at point 1",
                                                "faulted -> running"}));
}

TEST_P(StoreTest, CompletedNeedsEveryPointAndIsFinal) {
  const auto id = make_sweep(2);
  ASSERT_TRUE(store_->set_sweep_state(id, SweepState::running));
  ASSERT_TRUE(store_->insert_point(id, 0, sample_record(0)));
  const auto early = store_->set_sweep_state(id, SweepState::completed);
  EXPECT_EQ(early.code(), errc::invalid_transition);
  EXPECT_NE(early.error().message.find("1 of 2"), std::string::npos) << early.error().message;
  EXPECT_EQ(store_->get_sweep(id).value().state, SweepState::running) << "unchanged";

  ASSERT_TRUE(store_->insert_point(id, 1, sample_record(1)));
  ASSERT_TRUE(store_->set_sweep_state(id, SweepState::completed));
  const auto s = store_->get_sweep(id).value();
  EXPECT_EQ(s.state, SweepState::completed);
  EXPECT_TRUE(s.finished_at);
  EXPECT_EQ(s.points_stored, 2);
  EXPECT_EQ(store_->set_sweep_state(id, SweepState::running).code(), errc::invalid_transition);
  EXPECT_EQ(store_->set_sweep_state(id, SweepState::created).code(), errc::invalid_transition);
}

TEST_P(StoreTest, UnknownSweepIsNotFound) {
  EXPECT_EQ(store_->get_sweep(42).code(), errc::not_found);
  EXPECT_EQ(store_->set_sweep_state(42, SweepState::running).code(), errc::not_found);
  EXPECT_EQ(store_->insert_point(42, 0, sample_record(0)).code(), errc::not_found);
  EXPECT_EQ(store_->points(42).code(), errc::not_found);
  EXPECT_EQ(store_->missing_indices(42).code(), errc::not_found);
  EXPECT_EQ(store_->add_event(42, EventKind::log, "x").code(), errc::not_found);
  EXPECT_EQ(store_->events(42).code(), errc::not_found);
}

TEST_P(StoreTest, EveryFieldRoundTripsExactly) {
  constexpr std::int64_t kTotal = 60;  // covers every estimator, pwm, null pattern, truth, fault
  const auto id = make_sweep(kTotal);
  for (std::int64_t i = kTotal - 1; i >= 0; --i)  // stored out of order, read back by index
    ASSERT_TRUE(store_->insert_point(id, i, sample_record(i))) << i;
  const auto rows = store_->points(id);
  ASSERT_TRUE(rows) << rows.error().message;
  ASSERT_EQ(rows->size(), static_cast<std::size_t>(kTotal));
  for (std::int64_t i = 0; i < kTotal; ++i) {
    const auto& row = (*rows)[static_cast<std::size_t>(i)];
    EXPECT_EQ(row.index, i);
    EXPECT_EQ(exact_text(row.record), exact_text(sample_record(i))) << "point " << i;
  }
  // The samples do exercise what could be lost.
  const auto& r0 = (*rows)[0].record;
  EXPECT_TRUE(std::signbit(r0.angle_deg));
  EXPECT_FALSE(r0.truth);
  EXPECT_FALSE(r0.pos_err_mean_deg);
  EXPECT_EQ(std::bit_cast<std::uint64_t>((*rows)[1].record.truth->pmech_W), std::bit_cast<std::uint64_t>(1.5e-310));
  EXPECT_EQ((*rows)[8].record.fault, "link_loss, \"quoted\"");
  EXPECT_EQ((*rows)[13].record.fault, "overcurrent");
  EXPECT_EQ((*rows)[19].record.fault, "unknown");
  EXPECT_EQ((*rows)[19].record.fault_code_raw, 0x2310 + 19);
  EXPECT_EQ((*rows)[9].record.fault_code_raw, 4'294'967'295);
  EXPECT_FALSE((*rows)[13].record.fault_code_raw);
}

TEST_P(StoreTest, TheSamplesSetEveryField) {
  // The round trip above proves a field only if some sample gives it a value of its own: a field
  // added to the record and not to sample_record() fails here.
  const auto defaults = bench::to_json(bench::PointRecord{});
  auto with_truth = bench::PointRecord{};
  with_truth.truth = drivers::TruthWindow{};
  const auto default_truth = bench::to_json(with_truth)["truth"];
  std::set<std::string> set;
  for (std::int64_t i = 0; i < 60; ++i) {
    const auto j = bench::to_json(sample_record(i));
    for (const auto& [key, value] : j.items())
      if (value.dump() != defaults[key].dump()) set.insert(key);
    if (j["truth"].is_object())
      for (const auto& [key, value] : j["truth"].items())
        if (value.dump() != default_truth[key].dump()) set.insert("truth." + key);
  }
  bench::for_each_field(bench::kPointRecordFields, [&](const auto& f) { EXPECT_TRUE(set.contains(std::string(f.name))) << f.name; });
  bench::for_each_field(bench::kTruthFields, [&](const auto& f) { EXPECT_TRUE(set.contains("truth." + std::string(f.name))) << f.name; });
}

TEST_P(SqliteStoreTest, AValueTheRecordCannotHoldIsABadRecordNamingItsColumn) {
  // Another connection writes what the store never would; points() names the point and column.
  const auto read_after = [&](const std::string& set) -> std::string {
    const auto id = make_sweep(1);
    EXPECT_TRUE(store_->insert_point(id, 0, sample_record(1)));  // one with truth
    sqlite3* raw = nullptr;
    EXPECT_EQ(sqlite3_open((dir_ / "store.db").c_str(), &raw), SQLITE_OK);
    const std::string sql = "UPDATE points SET " + set + " WHERE sweep_id = " + std::to_string(id);
    EXPECT_EQ(sqlite3_exec(raw, sql.c_str(), nullptr, nullptr, nullptr), SQLITE_OK) << sqlite3_errmsg(raw);
    sqlite3_close(raw);
    const auto rows = store_->points(id);
    if (rows) return "read: " + exact_text(rows->at(0).record);
    EXPECT_EQ(rows.code(), errc::bad_record) << set;
    const std::string prefix = "point 0 of sweep " + std::to_string(id) + ": ";
    EXPECT_EQ(rows.error().message.rfind(prefix, 0), 0u) << rows.error().message;
    return rows.error().message.substr(prefix.size());
  };
  EXPECT_EQ(read_after("estimator = 'warp'"), "unknown estimator \"warp\"");
  EXPECT_EQ(read_after("pwm = ''"), "unknown pwm \"\"");
  EXPECT_EQ(read_after("samples = 4294967296"), "samples out of range");
  EXPECT_EQ(read_after("truth_json = '[1]'"), "truth_json is not a JSON object");
  EXPECT_EQ(read_after("truth_json = 'not json'"), "truth_json is not a JSON object");
  EXPECT_EQ(read_after("truth_json = json_remove(truth_json, '$.pcu_W')"), "truth_json has no pcu_W");
  EXPECT_EQ(read_after("truth_json = json_set(truth_json, '$.pfe_W', 'x')"), "truth_json.pfe_W is not a number");
  // A null in the truth object is JSON's NaN.
  auto nan_truth = sample_record(1);
  nan_truth.truth->pm_W = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(read_after("truth_json = json_set(truth_json, '$.pm_W', json('null'))"), "read: " + exact_text(nan_truth));
}

TEST_P(StoreTest, NanInARequiredFieldComesBackAsNan) {
  // SQLite cannot store NaN; the store writes NULL, which a required field reads as NaN.
  const auto id = make_sweep(1);
  auto r = sample_record(2);
  r.efficiency = std::numeric_limits<double>::quiet_NaN();
  r.ld_est_H = std::numeric_limits<double>::quiet_NaN();  // optional: reads back as null
  r.speed_rpm = std::numeric_limits<double>::infinity();
  ASSERT_TRUE(store_->insert_point(id, 0, r));
  const auto back = store_->points(id).value().at(0).record;
  EXPECT_TRUE(std::isnan(back.efficiency));
  EXPECT_FALSE(back.ld_est_H);
  EXPECT_EQ(back.speed_rpm, std::numeric_limits<double>::infinity());
}

TEST_P(StoreTest, DuplicatePointIsRejectedAndChangesNothing) {
  const auto id = make_sweep(5);
  ASSERT_TRUE(store_->insert_point(id, 3, sample_record(3)));
  const auto before = store_->points(id).value();
  const auto events_before = store_->events().value().size();

  const auto dup = store_->insert_point(id, 3, sample_record(4));
  ASSERT_FALSE(dup);
  EXPECT_EQ(dup.code(), errc::duplicate_point);
  EXPECT_NE(dup.error().message.find("point 3"), std::string::npos) << dup.error().message;

  const auto after = store_->points(id).value();
  ASSERT_EQ(after.size(), 1u);
  EXPECT_EQ(exact_text(after[0].record), exact_text(before[0].record));
  EXPECT_EQ(store_->events().value().size(), events_before);
  // The store is usable afterwards (no transaction left open).
  EXPECT_TRUE(store_->insert_point(id, 4, sample_record(4)));
}

TEST_P(StoreTest, IndexOutsideThePlanIsRejected) {
  const auto id = make_sweep(3);
  EXPECT_EQ(store_->insert_point(id, -1, sample_record(0)).code(), errc::invalid_argument);
  EXPECT_EQ(store_->insert_point(id, 3, sample_record(0)).code(), errc::invalid_argument);
  EXPECT_TRUE(store_->points(id).value().empty());
}

TEST_P(StoreTest, MissingIndicesAndWhereToResume) {
  const auto id = make_sweep(10);
  EXPECT_EQ(store_->first_missing_index(id).value(), 0);
  for (const std::int64_t i : {0, 1, 2, 5, 9}) ASSERT_TRUE(store_->insert_point(id, i, sample_record(i)));
  EXPECT_EQ(store_->missing_indices(id).value(), (std::vector<std::int64_t>{3, 4, 6, 7, 8}));
  EXPECT_EQ(store_->first_missing_index(id).value(), 3);
  for (const std::int64_t i : {3, 4, 6, 7, 8}) ASSERT_TRUE(store_->insert_point(id, i, sample_record(i)));
  EXPECT_TRUE(store_->missing_indices(id).value().empty());
  EXPECT_EQ(store_->first_missing_index(id).value(), std::nullopt);

  const auto empty = make_sweep(0, "empty");
  EXPECT_TRUE(store_->missing_indices(empty).value().empty());
}

TEST_P(StoreTest, EventsPerSweepAndBenchWide) {
  const auto a = make_sweep(1, "a");
  const auto b = make_sweep(1, "b");
  const auto e1 = store_->add_event(a, EventKind::fault, "overcurrent");
  ASSERT_TRUE(e1) << e1.error().message;
  ASSERT_TRUE(store_->add_event(std::nullopt, EventKind::log, "E-stop tested"));
  ASSERT_TRUE(store_->add_event(b, EventKind::log, "note on b"));

  const auto of_a = store_->events(a).value();
  ASSERT_EQ(of_a.size(), 2u);  // "created", then the fault
  EXPECT_EQ(of_a[1].id, *e1);
  EXPECT_EQ(of_a[1].kind, EventKind::fault);
  EXPECT_EQ(of_a[1].message, "overcurrent");
  EXPECT_FALSE(of_a[1].at.empty());

  const auto all = store_->events().value();
  ASSERT_EQ(all.size(), 5u);
  EXPECT_EQ(all[3].sweep_id, std::nullopt);
  EXPECT_EQ(all[3].kind, EventKind::log);
  for (std::size_t i = 1; i < all.size(); ++i) EXPECT_LT(all[i - 1].id, all[i].id);
}

TEST_P(StoreTest, ACommittedPointIsVisibleToAnotherConnectionAtOnce) {
  // insert_point's transaction is over when it returns: a second connection (as a reader process
  // would) sees the point without the store closing or checkpointing.
  const auto id = make_sweep(2);
  ASSERT_TRUE(store_->insert_point(id, 1, sample_record(1)));
  auto other = Store::open(target_);
  ASSERT_TRUE(other) << other.error().message;
  const auto rows = other->points(id).value();
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].index, 1);
  EXPECT_EQ(exact_text(rows[0].record), exact_text(sample_record(1)));
}

TEST_P(StoreTest, IntegrityCheckPassesOnAFreshAndAUsedDatabase) {
  EXPECT_TRUE(store_->integrity_check());
  const auto id = make_sweep(20);
  for (std::int64_t i = 0; i < 20; ++i) ASSERT_TRUE(store_->insert_point(id, i, sample_record(i)));
  const auto s = store_->integrity_check();
  EXPECT_TRUE(s) << (s ? "" : s.error().message);
}

TEST_P(StoreTest, ProgrammerErrorsThrow) {
  Result<std::int64_t> failed = make_error(errc::not_found, "x");
  EXPECT_THROW(static_cast<void>(failed.value()), std::logic_error);
  Store moved = std::move(*store_);
  EXPECT_THROW(static_cast<void>(store_->list_sweeps()), std::logic_error);
  EXPECT_TRUE(moved.list_sweeps());
}

}  // namespace
}  // namespace synbench::db
