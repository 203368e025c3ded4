// Storage that cannot be lost unseen, on real SQLite files: a database deleted or replaced under
// an open store, damaged pages and read-only files refused at open, sweeps left running by a
// crash marked aborted at start, and a full disk reported with SQLite's message.
#include <sqlite3.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "db/store.hpp"
#include "tests/db/sample_records.hpp"

namespace synbench::db {
namespace {

using testing::sample_record;
using testing::TempDir;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

std::int64_t make_sweep(Store& store, std::int64_t total) {
  SweepMeta meta;
  meta.name = "safety";
  meta.total_points = total;
  return store.create_sweep(meta).value();
}

// Runs SQL on a connection of its own (not the Store's), as another process would.
void raw_exec(const std::filesystem::path& path, const std::string& sql) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  char* err = nullptr;
  const int rc = sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &err);
  const std::string message = err ? err : "";
  sqlite3_free(err);
  sqlite3_close(db);
  ASSERT_EQ(rc, SQLITE_OK) << message;
}

TEST(FileLost, ADeletedDatabaseRefusesEveryWriteAndRead) {
  TempDir dir;
  const auto path = dir / "synbench.db";
  std::vector<Error> logged;
  StoreOptions options;
  options.on_error = [&](const Error& e) { logged.push_back(e); };
  auto store = Store::open(path, options);
  ASSERT_TRUE(store) << store.error().message;
  const auto id = make_sweep(*store, 10);
  ASSERT_TRUE(store->set_sweep_state(id, SweepState::running));
  ASSERT_TRUE(store->insert_point(id, 0, sample_record(0)));
  ASSERT_TRUE(logged.empty());

  // What the adversarial trial did: the file, its WAL and its index deleted while the sweep runs.
  for (const char* suffix : {"", "-wal", "-shm"}) ASSERT_EQ(std::remove((path.string() + suffix).c_str()), 0) << suffix;

  const auto s = store->insert_point(id, 1, sample_record(1));
  ASSERT_FALSE(s);
  EXPECT_EQ(s.code(), errc::file_lost);
  EXPECT_TRUE(contains(s.error().message, path.string() + " was deleted (link count 0)")) << s.error().message;
  // Nothing else is written into the lost file, and nothing is read from it as if it were there.
  EXPECT_EQ(store->set_sweep_state(id, SweepState::faulted, "x").code(), errc::file_lost);
  EXPECT_EQ(store->add_event(id, EventKind::log, "x").code(), errc::file_lost);
  SweepMeta another;
  another.name = "another";
  EXPECT_EQ(store->create_sweep(another).code(), errc::file_lost);
  EXPECT_EQ(store->list_sweeps().code(), errc::file_lost);
  EXPECT_EQ(store->get_sweep(id).code(), errc::file_lost);
  EXPECT_EQ(store->points(id).code(), errc::file_lost);
  EXPECT_EQ(store->missing_indices(id).code(), errc::file_lost);
  EXPECT_EQ(store->events().code(), errc::file_lost);
  // The log hook heard of it, with the same message.
  ASSERT_FALSE(logged.empty());
  EXPECT_EQ(logged.front().code, errc::file_lost);
  EXPECT_EQ(logged.front().message, s.error().message);
  EXPECT_FALSE(std::filesystem::exists(path)) << "the store did not bring the file back";
}

TEST(FileLost, AReplacedDatabaseIsNamedAsReplaced) {
  TempDir dir;
  const auto path = dir / "synbench.db";
  auto store = Store::open(path);
  ASSERT_TRUE(store) << store.error().message;
  const auto id = make_sweep(*store, 3);
  // Another (valid, empty) synbench database renamed over the open one.
  { ASSERT_TRUE(Store::open(dir / "other.db")); }
  std::filesystem::rename(dir / "other.db", path);
  const auto s = store->insert_point(id, 0, sample_record(0));
  ASSERT_FALSE(s);
  EXPECT_EQ(s.code(), errc::file_lost);
  EXPECT_TRUE(contains(s.error().message, path.string() + " was replaced by another file")) << s.error().message;
}

TEST(FileLost, ADeletedWriteAheadLogIsNamed) {
  // Without its WAL a commit would land in an unlinked log and be lost with it at the next crash.
  TempDir dir;
  const auto path = dir / "synbench.db";
  auto store = Store::open(path);
  ASSERT_TRUE(store) << store.error().message;
  const auto id = make_sweep(*store, 3);
  ASSERT_TRUE(std::filesystem::remove(path.string() + "-wal"));
  const auto s = store->insert_point(id, 0, sample_record(0));
  ASSERT_FALSE(s);
  EXPECT_EQ(s.code(), errc::file_lost);
  EXPECT_TRUE(contains(s.error().message, path.string() + "-wal (its write-ahead log) was deleted")) << s.error().message;
}

TEST(FileLost, AMovedDatabaseIsNamedAsMoved) {
  TempDir dir;
  const auto path = dir / "synbench.db";
  auto store = Store::open(path);
  ASSERT_TRUE(store) << store.error().message;
  std::filesystem::rename(path, dir / "elsewhere.db");
  const auto s = store->list_sweeps();
  ASSERT_FALSE(s);
  EXPECT_EQ(s.code(), errc::file_lost);
  EXPECT_TRUE(contains(s.error().message, "was moved away or renamed (the open file still has 1 links)")) << s.error().message;
}

TEST(Verify, DamagedPagesAreRefusedAtOpenNamingTheFile) {
  TempDir dir;
  const auto path = dir / "damaged.db";
  {
    auto store = Store::open(path);
    ASSERT_TRUE(store) << store.error().message;
    const auto id = make_sweep(*store, 400);
    for (int i = 0; i < 400; ++i) ASSERT_TRUE(store->insert_point(id, i, sample_record(i)));
  }  // the last connection's close checkpoints the WAL into the file and removes it
  ASSERT_FALSE(std::filesystem::exists(path.string() + "-wal"));
  const auto size = std::filesystem::file_size(path);
  ASSERT_GT(size, 40u * 4096u);
  {
    // Garbage over a page in the middle of the points' b-tree; page 1 (the schema) stays intact,
    // so the file still opens and only a check of its pages finds the damage.
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>((size / 4096 / 2) * 4096));
    const std::string garbage(4096, '\x5a');
    f.write(garbage.data(), static_cast<std::streamsize>(garbage.size()));
  }
  // Unchecked, the damaged file opens (what the trial found).
  { EXPECT_TRUE(Store::open(path)); }
  StoreOptions options;
  options.verify = true;
  const auto store = Store::open(path, options);
  ASSERT_FALSE(store);
  EXPECT_EQ(store.code(), errc::corrupt);
  EXPECT_TRUE(contains(store.error().message, path.string())) << store.error().message;
  EXPECT_TRUE(contains(store.error().message, "quick_check") || contains(store.error().message, "malformed"))
      << store.error().message;
}

TEST(Verify, AHealthyFileOpensWithTheChecks) {
  TempDir dir;
  const auto path = dir / "ok.db";
  StoreOptions options;
  options.verify = true;
  {
    auto store = Store::open(path, options);
    ASSERT_TRUE(store) << store.error().message;
    const auto id = make_sweep(*store, 2);
    ASSERT_TRUE(store->insert_point(id, 0, sample_record(0)));
  }
  auto store = Store::open(path, options);
  ASSERT_TRUE(store) << store.error().message;
  EXPECT_EQ(store->points(1).value().size(), 1u);
}

// Opens `path` as the unprivileged user `nobody` in a child process (root writes any file, so a
// read-only file can only be seen read-only without root's privilege); returns the child's
// message, or "opened".
std::string open_as_nobody(const std::filesystem::path& path) {
  int pipe_fd[2];
  if (::pipe(pipe_fd) != 0) return "pipe failed";
  const pid_t child = ::fork();
  if (child == 0) {
    ::close(pipe_fd[0]);
    std::string out;
    if (::geteuid() == 0 && (::setgid(65534) != 0 || ::setuid(65534) != 0)) {
      out = "setuid failed";
    } else {
      StoreOptions options;
      options.verify = true;
      auto store = Store::open(path, options);
      out = store ? std::string("opened")
                  : std::string(store.code() == errc::read_only ? "read_only: " : "other: ") + store.error().message;
    }
    (void)!::write(pipe_fd[1], out.data(), out.size());
    ::_exit(0);
  }
  ::close(pipe_fd[1]);
  std::string got;
  char buf[512];
  for (ssize_t n; (n = ::read(pipe_fd[0], buf, sizeof buf)) > 0;) got.append(buf, static_cast<std::size_t>(n));
  ::close(pipe_fd[0]);
  int status = 0;
  ::waitpid(child, &status, 0);
  return got;
}

TEST(ReadOnly, AFileThatCannotBeWrittenIsRefusedAtOpen) {
  TempDir dir;
  const auto path = dir / "ro.db";
  { ASSERT_TRUE(Store::open(path)); }
  ::chmod(dir.path().c_str(), 0777);
  ::chmod(path.c_str(), 0444);
  const std::string got = open_as_nobody(path);
  EXPECT_TRUE(contains(got, "read_only: ")) << got;
  EXPECT_TRUE(contains(got, path.string())) << got;
  EXPECT_TRUE(contains(got, "synbench must write it")) << got;
}

TEST(ReadOnly, ADirectoryWhereTheWalCannotBeCreatedIsRefusedAtOpen) {
  TempDir dir;
  const auto path = dir / "rodir.db";
  { ASSERT_TRUE(Store::open(path)); }
  ASSERT_FALSE(std::filesystem::exists(path.string() + "-wal"));
  ::chmod(path.c_str(), 0666);   // the file itself is writable ...
  ::chmod(dir.path().c_str(), 0555);  // ... but no -wal can be created beside it
  const std::string got = open_as_nobody(path);
  ::chmod(dir.path().c_str(), 0700);
  EXPECT_TRUE(contains(got, "read_only: ")) << got;
  EXPECT_TRUE(contains(got, path.string())) << got;
}

TEST(LeftRunning, ASweepOfAGoneProcessIsMarkedAbortedWithItsEvent) {
  TempDir dir;
  const auto path = dir / "crashed.db";
  auto store = Store::open(path);
  ASSERT_TRUE(store) << store.error().message;
  const auto gone = make_sweep(*store, 5);
  const auto old = make_sweep(*store, 5);
  const auto ours = make_sweep(*store, 5);
  const auto paused = make_sweep(*store, 5);
  for (auto id : {gone, old, ours, paused}) ASSERT_TRUE(store->set_sweep_state(id, SweepState::running));
  ASSERT_TRUE(store->set_sweep_state(paused, SweepState::paused));
  ASSERT_TRUE(store->insert_point(gone, 0, sample_record(0)));
  // A process that ran and ended: its pid is free (or another process's, with another start).
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);
  raw_exec(path, "UPDATE sweeps SET owner_pid = " + std::to_string(child) + " WHERE id = " + std::to_string(gone));
  // A sweep left running by a synbench that did not record owners.
  raw_exec(path, "UPDATE sweeps SET owner_host = NULL, owner_pid = NULL, owner_start = NULL WHERE id = " +
                     std::to_string(old));

  const auto left = store->abort_left_running();
  ASSERT_TRUE(left) << left.error().message;
  ASSERT_EQ(left->size(), 3u);
  EXPECT_EQ((*left)[0].sweep_id, gone);
  EXPECT_TRUE((*left)[0].marked_aborted);
  EXPECT_TRUE(contains((*left)[0].message, "pid " + std::to_string(child))) << (*left)[0].message;
  EXPECT_TRUE((*left)[1].marked_aborted);
  EXPECT_EQ((*left)[2].sweep_id, ours);
  EXPECT_FALSE((*left)[2].marked_aborted) << "this process still runs it";
  EXPECT_TRUE(contains((*left)[2].message, "left alone")) << (*left)[2].message;

  const auto s = store->get_sweep(gone).value();
  EXPECT_EQ(s.state, SweepState::aborted);
  EXPECT_EQ(s.points_stored, 1);
  ASSERT_TRUE(s.last_error);
  EXPECT_TRUE(contains(*s.last_error, "marked aborted at start: left running by a previous process (pid " +
                                          std::to_string(child) + " on "))
      << *s.last_error;
  const auto events = store->events(gone).value();
  EXPECT_TRUE(contains(events.back().message, "running -> aborted: marked aborted at start")) << events.back().message;
  EXPECT_EQ(store->get_sweep(old).value().state, SweepState::aborted);
  EXPECT_TRUE(contains(store->get_sweep(old).value().last_error.value(), "an unrecorded process"));
  EXPECT_EQ(store->get_sweep(ours).value().state, SweepState::running);
  EXPECT_EQ(store->get_sweep(paused).value().state, SweepState::paused);
  // Aborted, it resumes as before.
  EXPECT_TRUE(store->set_sweep_state(gone, SweepState::running));
  // Nothing left to mark.
  EXPECT_EQ(store->abort_left_running().value().size(), 2u);
}

TEST(LeftRunning, AnotherBootsSweepIsGoneAndAnotherContainersIsLeftAlone) {
  TempDir dir;
  const auto path = dir / "owners.db";
  auto store = Store::open(path);
  ASSERT_TRUE(store) << store.error().message;
  const auto rebooted = make_sweep(*store, 1);
  const auto container = make_sweep(*store, 1);
  for (auto id : {rebooted, container}) ASSERT_TRUE(store->set_sweep_state(id, SweepState::running));
  raw_exec(path, "UPDATE sweeps SET owner_start = 'another-boot:1' WHERE id = " + std::to_string(rebooted));
  raw_exec(path, "UPDATE sweeps SET owner_host = 'a-container-beside-us' WHERE id = " + std::to_string(container));
  const auto left = store->abort_left_running().value();
  ASSERT_EQ(left.size(), 2u);
  EXPECT_TRUE(left[0].marked_aborted) << left[0].message;
  EXPECT_FALSE(left[1].marked_aborted) << left[1].message;
  EXPECT_TRUE(contains(left[1].message, "cannot see")) << left[1].message;
}

TEST(DiskFull, SqliteFullIsReportedAsDiskFullNamingTheFileWithSqlitesMessage) {
  TempDir dir;
  const auto path = dir / "full.db";
  std::int64_t id = 0, pages = 0;
  {
    auto store = Store::open(path);
    ASSERT_TRUE(store) << store.error().message;
    id = make_sweep(*store, 1000);
    pages = std::stoll(store->pragma("page_count").value());
  }
  // A size limit a few pages above what is there: the points fill it as a disk would fill.
  std::vector<Error> logged;
  StoreOptions options;
  options.max_page_count = pages + 3;
  options.on_error = [&](const Error& e) { logged.push_back(e); };
  auto store = Store::open(path, options);
  ASSERT_TRUE(store) << store.error().message;
  Status last;
  int stored = 0;
  for (int i = 0; i < 1000 && last.ok(); ++i) {
    last = store->insert_point(id, i, sample_record(i));
    if (last) ++stored;
  }
  ASSERT_FALSE(last) << "the limit was never reached";
  EXPECT_GT(stored, 0);
  EXPECT_EQ(last.code(), errc::disk_full) << last.error().message;
  const std::string& m = last.error().message;
  EXPECT_TRUE(contains(m, path.string())) << m;
  EXPECT_TRUE(contains(m, "disk full")) << m;
  EXPECT_TRUE(contains(m, sqlite3_errstr(SQLITE_FULL))) << m;  // SQLite's own text
  EXPECT_TRUE(contains(m, "SQLite code 13")) << m;
  EXPECT_TRUE(contains(m, "point " + std::to_string(stored))) << m;
  ASSERT_EQ(logged.size(), 1u);
  EXPECT_EQ(logged[0].message, m);
  // The points stored before are intact, the failed one is absent.
  EXPECT_EQ(store->points(id).value().size(), static_cast<std::size_t>(stored));
}

TEST(Errors, RefusalsOfTheCallerAreNotStorageFailures) {
  EXPECT_FALSE(is_storage_failure(errc::not_found));
  EXPECT_FALSE(is_storage_failure(errc::duplicate_point));
  EXPECT_FALSE(is_storage_failure(errc::invalid_transition));
  EXPECT_TRUE(is_storage_failure(errc::file_lost));
  EXPECT_TRUE(is_storage_failure(errc::disk_full));
  EXPECT_TRUE(is_storage_failure(errc::io));
  EXPECT_FALSE(is_storage_failure(std::make_error_code(std::errc::io_error)));
}

}  // namespace
}  // namespace synbench::db
