// Crash safety: a child process stores a sweep's points and is SIGKILLed at random moments; after
// every kill the file must pass integrity_check, hold every point whose insert had returned (the
// child printed it), hold each index once with its exact record, and the next run must resume at
// the first missing index. A last run, not killed, completes the sweep.
//
// Runs: 20 by default; SYNBENCH_DB_CRASH_RUNS=100 for the benchmark run. Seed:
// SYNBENCH_DB_CRASH_SEED (fixed by default, so a failure repeats).
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <random>
#include <set>
#include <thread>

#include "db/store.hpp"
#include "tests/db/sample_records.hpp"

namespace synbench::db {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

long env_or(const char* name, long fallback) {
  const char* v = std::getenv(name);
  return v && *v ? std::strtol(v, nullptr, 10) : fallback;
}

// The child process with its stdout on a pipe, read line by line.
class Child {
 public:
  Child(const std::filesystem::path& db, std::int64_t total) {
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error("pipe");
    pid_ = fork();
    if (pid_ < 0) throw std::runtime_error("fork");
    if (pid_ == 0) {
      dup2(fds[1], STDOUT_FILENO);  // dup2 clears CLOEXEC on the copy
      const std::string total_text = std::to_string(total);
      execl(SYNBENCH_DB_CRASH_CHILD, SYNBENCH_DB_CRASH_CHILD, db.c_str(), total_text.c_str(),
            static_cast<char*>(nullptr));
      _exit(127);
    }
    close(fds[1]);
    fd_ = fds[0];
  }
  ~Child() {
    if (pid_ > 0 && !reaped_) {
      kill(pid_, SIGKILL);
      wait_exit();
    }
    if (fd_ >= 0) close(fd_);
  }
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;

  // The next line, or nullopt at end of output; fails the test after `timeout`.
  std::optional<std::string> line(std::chrono::milliseconds timeout = 20s) {
    const auto deadline = Clock::now() + timeout;
    for (;;) {
      if (const auto nl = buf_.find('\n'); nl != std::string::npos) {
        std::string l = buf_.substr(0, nl);
        buf_.erase(0, nl + 1);
        return l;
      }
      if (eof_) return std::nullopt;
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
      if (left <= 0ms) throw std::runtime_error("child output timed out");
      pollfd p{fd_, POLLIN, 0};
      if (poll(&p, 1, static_cast<int>(left.count())) < 0 && errno != EINTR) throw std::runtime_error("poll");
      char chunk[4096];
      const ssize_t n = read(fd_, chunk, sizeof chunk);
      if (n == 0) eof_ = true;
      else if (n > 0) buf_.append(chunk, static_cast<std::size_t>(n));
      else if (errno != EINTR && errno != EAGAIN) throw std::runtime_error("read");
    }
  }

  void kill_now() { kill(pid_, SIGKILL); }

  // The wait status.
  int wait_exit() {
    int status = 0;
    while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
    reaped_ = true;
    return status;
  }

 private:
  pid_t pid_ = -1;
  int fd_ = -1;
  std::string buf_;
  bool eof_ = false;
  bool reaped_ = false;
};

// What one run of the child said.
struct RunOutput {
  std::optional<std::int64_t> resumed_at;  // its "resume" line, if it got that far
  std::vector<std::int64_t> committed;     // indices whose insert_point had returned
  bool done = false;
};

void parse(const std::string& l, RunOutput& out) {
  if (l.rfind("resume ", 0) == 0) out.resumed_at = std::stoll(l.substr(7));
  else if (l == "done") out.done = true;
  else out.committed.push_back(std::stoll(l));
}

struct Verified {
  std::set<std::int64_t> stored;  // indices in the file
  std::optional<std::int64_t> first_missing;
};

// The checks after every run. `printed`: every index any run printed so far.
Verified verify(const std::filesystem::path& db, const std::set<std::int64_t>& printed, std::int64_t total) {
  Verified v;
  auto store = Store::open(db);
  EXPECT_TRUE(store) << store.error().message;
  if (!store) return v;
  const auto integrity = store->integrity_check();
  EXPECT_TRUE(integrity) << (integrity ? "" : integrity.error().message);
  const auto sweeps = store->list_sweeps().value();
  EXPECT_LE(sweeps.size(), 1u) << "a killed create_sweep must not leave a second sweep";
  if (sweeps.empty()) {
    EXPECT_TRUE(printed.empty());
    v.first_missing = 0;
    return v;
  }
  const auto rows = store->points(sweeps[0].id).value();
  auto& stored = v.stored;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const auto& row = rows[k];
    if (k > 0) {
      EXPECT_LT(rows[k - 1].index, row.index) << "duplicate or unordered index";
    }
    EXPECT_TRUE(row.index >= 0 && row.index < total);
    EXPECT_EQ(testing::exact_text(row.record), testing::exact_text(testing::sample_record(row.index)))
        << "point " << row.index << " stored with other contents";
    stored.insert(row.index);
  }
  EXPECT_EQ(stored.size(), rows.size()) << "duplicates";
  for (const auto i : printed) EXPECT_TRUE(stored.count(i)) << "committed point " << i << " lost";
  v.first_missing = store->first_missing_index(sweeps[0].id).value();
  return v;
}

TEST(CrashSafety, KilledSweepsLoseNothingCommittedAndResume) {
  const int runs = static_cast<int>(env_or("SYNBENCH_DB_CRASH_RUNS", 20));
  const auto seed = static_cast<std::uint32_t>(env_or("SYNBENCH_DB_CRASH_SEED", 20240611));
  // At most ~45 points are stored per killed run, so the sweep outlasts the kills and the last run
  // still has work to do.
  const std::int64_t total = 50 * runs + 200;
  std::mt19937 rng(seed);
  testing::TempDir dir;
  const auto db = dir / "crash.db";

  std::set<std::int64_t> printed;  // every index a child printed: its insert_point had returned
  std::set<std::int64_t> stored;   // the file's indices after the previous run
  std::optional<std::int64_t> expected_resume = 0;
  int early_kills = 0;
  std::size_t in_flight_committed = 0;  // stored by a run but not printed before its kill
  double interval_s = 1e-3;             // mean time between two printed points, measured as runs go
  double startup_s = 5e-3;              // spawn to the "resume" line, measured as runs go

  for (int run = 0; run < runs; ++run) {
    const auto spawned = Clock::now();
    Child child(db, total);
    RunOutput out;
    // One kill in five lands anywhere in the child's start-up: exec, open, migration,
    // create_sweep, the state change, missing_indices. The others wait for 1..40 committed points, then a random fraction of a
    // point's time, so the kill falls at a random phase of insert_point (bind, insert, commit,
    // fsync) or of the print after it.
    if (std::uniform_int_distribution<int>(0, 4)(rng) == 0) {
      ++early_kills;
      std::this_thread::sleep_for(
          std::chrono::duration<double>(std::uniform_real_distribution<double>(0, 1.2)(rng) * startup_s));
    } else {
      const int wait_for = std::uniform_int_distribution<int>(1, 40)(rng);
      int seen = 0;
      Clock::time_point first{};
      while (seen < wait_for) {
        const auto l = child.line();
        if (!l) break;  // the child ended (it should not before the kill)
        parse(*l, out);
        if (l->rfind("resume ", 0) == 0) startup_s = std::chrono::duration<double>(Clock::now() - spawned).count();
        if (l->rfind("resume ", 0) == 0 || *l == "done") continue;
        if (seen++ == 0) first = Clock::now();
      }
      if (seen > 1) interval_s = std::chrono::duration<double>(Clock::now() - first).count() / (seen - 1);
      std::this_thread::sleep_for(
          std::chrono::duration<double>(std::uniform_real_distribution<double>(0, 1.0)(rng) * interval_s));
    }
    child.kill_now();
    const int status = child.wait_exit();
    while (const auto l = child.line()) parse(*l, out);
    ASSERT_FALSE(out.done) << "run " << run << ": sweep finished before the kill; raise total";
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL)
        << "run " << run << ": the child failed on its own (status " << status << ")";

    if (out.resumed_at) {
      EXPECT_EQ(out.resumed_at, expected_resume.value_or(-1)) << "run " << run;
    }
    for (std::size_t k = 0; k < out.committed.size(); ++k) {
      EXPECT_FALSE(stored.count(out.committed[k])) << "run " << run << " stored " << out.committed[k] << " again";
      if (k > 0) {
        EXPECT_LT(out.committed[k - 1], out.committed[k]);
      }
      printed.insert(out.committed[k]);
    }
    auto v = verify(db, printed, total);
    // The child prints right after each commit returns, so a kill leaves at most one committed
    // point unprinted: the one between its commit and its print.
    const auto added = v.stored.size() - stored.size();
    EXPECT_TRUE(added == out.committed.size() || added == out.committed.size() + 1)
        << "run " << run << ": " << added << " stored, " << out.committed.size() << " printed";
    in_flight_committed += added - out.committed.size();
    if (::testing::Test::HasFailure()) FAIL() << "after run " << run << " (seed " << seed << ")";
    stored = std::move(v.stored);
    expected_resume = v.first_missing;
  }
  const std::size_t stored_before_final = stored.size();

  // The last run is not killed: it resumes where the file says and completes the sweep.
  Child child(db, total);
  RunOutput out;
  while (const auto l = child.line(60s)) parse(*l, out);
  const int status = child.wait_exit();
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "final run status " << status;
  EXPECT_TRUE(out.done);
  EXPECT_EQ(out.resumed_at, expected_resume.value_or(-1));
  for (const auto i : out.committed) {
    EXPECT_FALSE(stored.count(i)) << "final run stored " << i << " again";
    printed.insert(i);
  }
  const auto v = verify(db, printed, total);
  EXPECT_EQ(v.stored.size(), static_cast<std::size_t>(total));
  EXPECT_EQ(v.stored.size(), stored_before_final + out.committed.size());
  EXPECT_EQ(v.first_missing, std::nullopt);
  auto store = Store::open(db);
  ASSERT_TRUE(store);
  const auto sweep = store->list_sweeps().value().at(0);
  EXPECT_EQ(sweep.state, SweepState::completed);
  EXPECT_EQ(sweep.points_stored, total);

  std::printf("[ crash    ] %d kills (%d before the first point), seed %u: %zu points stored by "
              "killed runs (%zu of them committed but not yet printed at the kill), %zu by the last "
              "run, %lld in all, every one verified\n",
              runs, early_kills, seed, stored_before_final, in_flight_committed, out.committed.size(),
              static_cast<long long>(total));
  ::testing::Test::RecordProperty("kills", runs);
  ::testing::Test::RecordProperty("points_by_killed_runs", static_cast<int>(stored_before_final));
  ::testing::Test::RecordProperty("points_total", static_cast<int>(total));
}

}  // namespace
}  // namespace synbench::db
