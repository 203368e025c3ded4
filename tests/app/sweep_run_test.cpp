// The sweep runner when its store fails: a database file deleted while the sweep runs faults the
// sweep with the store's own message (the file and what happened), after an ordered stop, and no
// point after the deletion is counted as stored. On the twin's virtual clock, as `synbench sweep`.
#include "app/sweep_run.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <unistd.h>

#include "bench/sweep_plan.hpp"
#include "emulator/twin_bench.hpp"

namespace synbench::app {
namespace {

// Deletes the database (with its WAL and index) right after the first point's commit returned.
class DeleteAfterFirstPoint final : public bench::SweepSink {
 public:
  explicit DeleteAfterFirstPoint(std::filesystem::path path) : path_(std::move(path)) {}
  std::error_code store_point(std::size_t, const bench::PointRecord&) override {
    if (++committed == 1)
      for (const char* suffix : {"", "-wal", "-shm"}) std::remove((path_.string() + suffix).c_str());
    return {};
  }
  std::size_t committed = 0;

 private:
  std::filesystem::path path_;
};

TEST(SweepRun, ADatabaseDeletedDuringTheSweepFaultsItWithTheStoresMessage) {
  const auto dir = std::filesystem::temp_directory_path() / ("synbench_sweep_run_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto db_path = dir / "synbench.db";
  auto parsed = bench::parse_sweep_plan(synbench::Json::parse(R"({"name": "lost", "window_s": 0.2,
      "dimensions": {"speed_rpm": [300], "load_Nm": [0.5], "angle_deg": [45, 50, 55, 60]}})"));
  ASSERT_TRUE(parsed.plan) << (parsed.errors.empty() ? "" : parsed.errors[0].reason);
  auto opened = db::Store::open(db_path);
  ASSERT_TRUE(opened) << opened.error().message;
  db::Store store = std::move(*opened);
  db::SweepMeta meta;
  meta.name = "lost";
  meta.plan = bench::to_json(*parsed.plan);
  meta.total_points = static_cast<std::int64_t>(bench::estimate(*parsed.plan).points);
  const auto id = store.create_sweep(meta).value();

  emulator::TwinBench twin(emulator::TwinConfig{});
  bench::SafetySupervisor supervisor(twin.devices(), bench::SafetyLimits{});
  DeleteAfterFirstPoint observer(db_path);
  SweepRunOptions options;
  options.observer = &observer;
  SweepRun run(twin.devices(), supervisor, store, id, *parsed.plan, {}, options);
  ASSERT_FALSE(run.begin());
  double t = twin.clock().now_s();
  while (!run.finished() && t < 600.0) {
    t += 0.01;
    twin.clock().wait_until(t);
    supervisor.tick(t);
    run.tick(t);
  }
  ASSERT_TRUE(run.finished());
  EXPECT_EQ(run.final_state(), db::SweepState::faulted);
  const std::string& error = run.engine().error();
  EXPECT_NE(error.find("storing point 1 failed: " + db_path.string() + " was deleted (link count 0)"), std::string::npos)
      << error;
  EXPECT_EQ(observer.committed, 1u) << "no point after the deletion is reported stored";
  EXPECT_EQ(run.engine().progress().done, 1u);
  // The bench was stopped in order, not left running: read back once the stop's disable is seen.
  for (int i = 0; i < 100; ++i) {
    t += 0.01;
    twin.clock().wait_until(t);
    supervisor.tick(t);
  }
  ASSERT_TRUE(supervisor.synrm());
  EXPECT_FALSE(drivers::running(supervisor.synrm()->state));
  EXPECT_FALSE(supervisor.tripped());
  // Recording the final state cannot succeed either, and says why.
  const auto finish = run.finish();
  ASSERT_TRUE(finish);
  EXPECT_NE(finish->find("was deleted"), std::string::npos) << *finish;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace synbench::app
