// A study shard into the store on the twin's virtual clock: each sample one sweep under its key,
// an interrupted shard resumes its sample at the first missing point, a re-run skips complete
// samples, and a shard runs its own samples only. (The backend is built here: app/ never sees
// the twin; server/cli/study_command.cpp builds the same from the deviated twin config.)
#include "app/study_run.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <unistd.h>

#include "app/bench_description.hpp"
#include "drivers/json.hpp"
#include "emulator/plant_deviation.hpp"
#include "emulator/twin_bench.hpp"
#include "tests/app/twin_only.hpp"

namespace synbench::app {
namespace {

class CountPoints final : public bench::SweepSink {
 public:
  std::error_code store_point(std::size_t, const bench::PointRecord&) override {
    ++committed;
    return {};
  }
  std::size_t committed = 0;
};

bench::StudyPlan plan() {
  auto parsed = bench::parse_study_plan(synbench::Json::parse(R"({"name": "unit", "sweep": {"name": "s",
      "window_s": 0.2, "thermal": {"enabled": false},
      "dimensions": {"speed_rpm": [300], "load_Nm": [0.5], "angle_deg": [50, 60]}},
      "grid": {"ld_pct": [-25, 0, 25]}})"));
  EXPECT_TRUE(parsed.plan);
  return *parsed.plan;
}

StudyShardOptions options(CountPoints& counter, std::function<bool()> interrupted = {}) {
  StudyShardOptions o;
  o.make_backend = [](const bench::StudySample& s, std::string& error) -> std::unique_ptr<BenchBackend> {
    emulator::TwinConfig c;
    for (const auto& [p, v] : s.deviation)
      if (auto e = emulator::apply_plant_deviation(c, bench::name(p), v)) {
        error = *e;
        return nullptr;
      }
    return std::make_unique<TwinOnly>(c);
  };
  o.bench_config = [](const bench::StudySample& s) { return synbench::Json{{"ld_pct", s.deviation[0].second}}; };
  o.observer = &counter;
  o.interrupted = std::move(interrupted);
  return o;
}

TEST(StudyRun, InterruptedShardResumesWithoutDuplicatesAndSkipsCompleteSamples) {
  const auto dir = std::filesystem::temp_directory_path() / ("synbench_study_run_test_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  auto store = std::move(db::Store::open(dir / "study.db").value());
  const bench::StudyPlan p = plan();

  // Shard 1/2 alone: sample 1 only.
  CountPoints c1;
  auto r1 = run_study_shard(store, p, {1, 2}, options(c1));
  ASSERT_EQ(r1.samples.size(), 1u);
  EXPECT_EQ(r1.samples[0].index, 1u);
  EXPECT_EQ(r1.samples[0].result, StudySampleResult::completed) << r1.samples[0].error;
  EXPECT_EQ(c1.committed, 2u);

  // Shard 0/2 stopped after its first point: sample 0 is left with one point.
  CountPoints c2;
  auto r2 = run_study_shard(store, p, {0, 2}, options(c2, [&] { return c2.committed >= 1; }));
  EXPECT_TRUE(r2.interrupted);
  ASSERT_EQ(r2.samples.size(), 1u);
  EXPECT_EQ(r2.samples[0].result, StudySampleResult::interrupted);
  EXPECT_EQ(r2.samples[0].points_after, 1u);

  // Re-run: sample 0 resumes at its second point, sample 2 runs whole.
  CountPoints c3;
  auto r3 = run_study_shard(store, p, {0, 2}, options(c3));
  ASSERT_TRUE(r3.ok());
  ASSERT_EQ(r3.samples.size(), 2u);
  EXPECT_EQ(r3.samples[0].points_before, 1u);
  EXPECT_EQ(r3.samples[0].points_after, 2u);
  EXPECT_EQ(r3.samples[1].points_before, 0u);
  EXPECT_EQ(c3.committed, 3u);

  // A third run stores nothing.
  CountPoints c4;
  auto r4 = run_study_shard(store, p, {0, 1}, options(c4));
  ASSERT_TRUE(r4.ok());
  EXPECT_EQ(c4.committed, 0u);
  for (const auto& s : r4.samples) EXPECT_EQ(s.result, StudySampleResult::already_complete);

  // One sweep per sample, under its key, with its deviation, every index once.
  auto sweeps = study_sweeps(store, p).value();
  ASSERT_EQ(sweeps.size(), 3u);
  const auto all = store.list_sweeps().value();
  EXPECT_EQ(all.size(), 3u);
  for (const auto& [i, sweep] : sweeps) {
    EXPECT_EQ(sweep.meta.name, bench::sample_key(p, i));
    EXPECT_EQ(sweep.state, db::SweepState::completed);
    EXPECT_EQ(sweep.meta.calibration["study"]["deviation"]["ld_pct"], bench::sample(p, i).deviation[0].second);
    std::set<std::int64_t> indices;
    const auto rows = store.points(sweep.id).value();
    for (const auto& row : rows) EXPECT_TRUE(indices.insert(row.index).second);
    EXPECT_EQ(indices, (std::set<std::int64_t>{0, 1}));
  }
  std::filesystem::remove_all(dir);
}

TEST(StudyRun, ASampleWhosePlantCannotBeBuiltFailsAndTheShardGoesOn) {
  const auto dir = std::filesystem::temp_directory_path() / ("synbench_study_run_bad_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  auto store = std::move(db::Store::open(dir / "study.db").value());
  CountPoints c;
  auto o = options(c);
  auto make = o.make_backend;
  o.make_backend = [make](const bench::StudySample& s, std::string& error) -> std::unique_ptr<BenchBackend> {
    if (s.index == 0) {
      error = "no plant for sample 0";
      return nullptr;
    }
    return make(s, error);
  };
  auto p = plan();
  p.grid[0].second = {-25, 0};
  auto r = run_study_shard(store, p, {0, 1}, o);
  ASSERT_EQ(r.samples.size(), 2u);
  EXPECT_EQ(r.samples[0].result, StudySampleResult::failed);
  EXPECT_EQ(r.samples[0].error, "no plant for sample 0");
  EXPECT_EQ(r.samples[1].result, StudySampleResult::completed);
  EXPECT_FALSE(r.ok());
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace synbench::app
