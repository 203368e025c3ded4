// A twin sweep on two jobs into a SQLite file (app/parallel_sweep.hpp): each job measures only
// its groups, the store gets every point once in point order, an interruption leaves a resumable
// sweep, and the resume on two jobs completes it. Threaded: the jobs' twins run on their own
// threads (the tsan preset runs it).
#include "app/parallel_sweep.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <set>
#include <unistd.h>

#include "drivers/json.hpp"
#include "emulator/twin_bench.hpp"
#include "tests/app/twin_only.hpp"

namespace synbench::app {
namespace {

// The written points as the observer is told of them (on the calling thread).
class Written final : public bench::SweepSink {
 public:
  std::error_code store_point(std::size_t index, const bench::PointRecord&) override {
    indices.push_back(index);
    return {};
  }
  std::vector<std::size_t> indices;
};

// 2 speeds x 2 loads, one configuration: 4 groups of 3 angles, 12 points.
bench::SweepPlan plan() {
  auto parsed = bench::parse_sweep_plan(synbench::Json::parse(R"({"name": "jobs", "window_s": 0.2,
      "thermal": {"enabled": false},
      "dimensions": {"speed_rpm": [300, 600], "load_Nm": [0.5, 1.5], "angle_deg": [48, 56, 64]}})"));
  EXPECT_TRUE(parsed.plan);
  return *parsed.plan;
}

ParallelSweepOptions options(Written& written, std::function<bool()> interrupted = {}) {
  ParallelSweepOptions o;
  o.jobs = 2;
  o.make_backend = [] { return std::make_unique<TwinOnly>(); };
  o.observer = &written;
  o.interrupted = std::move(interrupted);
  return o;
}

std::vector<std::size_t> stored_indices(db::Store& store, std::int64_t id) {
  std::vector<std::size_t> out;
  const auto rows = store.points(id).value();  // a copy: a range-for over a temporary's value() dangles
  for (const auto& row : rows) out.push_back(static_cast<std::size_t>(row.index));
  return out;
}

TEST(ParallelSweep, TwoJobsStoreEveryPointOnceInPointOrderAndAnInterruptedSweepResumes) {
  const auto dir = std::filesystem::temp_directory_path() / ("synbench_parallel_sweep_test_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  auto store = std::move(db::Store::open(dir / "jobs.db").value());
  const bench::SweepPlan p = plan();
  db::SweepMeta meta;
  meta.name = "jobs";
  meta.plan = bench::to_json(p);
  meta.total_points = 12;

  // Uninterrupted.
  const auto whole = store.create_sweep(meta).value();
  Written w1;
  const auto r1 = run_parallel_sweep(store, whole, p, {}, options(w1));
  EXPECT_EQ(r1.state, db::SweepState::completed) << r1.error;
  EXPECT_EQ(r1.written, 12u);
  std::vector<std::size_t> all(12);
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  EXPECT_EQ(w1.indices, all) << "written in point order";
  EXPECT_EQ(stored_indices(store, whole), all);
  EXPECT_EQ(store.get_sweep(whole).value().state, db::SweepState::completed);
  // Every record is its index's operating point, measured there: group 0 (job 0) and group 1
  // (job 1) are 300 rpm at 0.5 and 1.5 N m, groups 2 and 3 the same at 600 rpm.
  const auto rows = store.points(whole).value();
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i].record;
    EXPECT_DOUBLE_EQ(r.speed_rpm, i < 6 ? 300.0 : 600.0) << i;
    EXPECT_DOUBLE_EQ(r.load_Nm, (i / 3) % 2 ? 1.5 : 0.5) << i;
    EXPECT_NEAR(r.speed_meas_rpm, r.speed_rpm, 5.0) << i;
    EXPECT_GT(r.pdcm_W, 10.0) << i;
  }

  // Interrupted after the 4th written point: aborted, what was measured stored once.
  const auto cut = store.create_sweep(meta).value();
  Written w2;
  const auto r2 = run_parallel_sweep(store, cut, p, {}, options(w2, [&] { return w2.indices.size() >= 4; }));
  EXPECT_EQ(r2.state, db::SweepState::aborted) << r2.error;
  const auto part = stored_indices(store, cut);
  EXPECT_GE(part.size(), 4u);
  EXPECT_LT(part.size(), 12u);
  EXPECT_EQ(std::set<std::size_t>(part.begin(), part.end()).size(), part.size()) << "each point once";
  EXPECT_EQ(store.get_sweep(cut).value().state, db::SweepState::aborted);

  // Resumed on two jobs: only the missing points are measured.
  std::map<std::size_t, bench::PointRecord> stored;
  const auto cut_rows = store.points(cut).value();
  for (const auto& row : cut_rows) stored[static_cast<std::size_t>(row.index)] = row.record;
  Written w3;
  const auto r3 = run_parallel_sweep(store, cut, p, stored, options(w3));
  EXPECT_EQ(r3.state, db::SweepState::completed) << r3.error;
  EXPECT_EQ(r3.written, 12u - part.size());
  auto resumed = stored_indices(store, cut);
  std::sort(resumed.begin(), resumed.end());
  EXPECT_EQ(resumed, all);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace synbench::app
