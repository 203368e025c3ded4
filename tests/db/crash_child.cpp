// The process the crash test kills: opens a store, creates (first run) or resumes its one sweep,
// and stores the missing points in order, writing each index to stdout as soon as insert_point
// has returned. A printed index is therefore a point whose commit had returned before the kill.
//
// usage: db_crash_child <database> <total_points>
// stdout: "resume <first missing index>", then one index per line, then "done".
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "db/store.hpp"
#include "tests/db/sample_records.hpp"

namespace {

// write(2), not stdio: nothing waits in a user-space buffer when the SIGKILL comes.
void say(const std::string& line) {
  const std::string s = line + "\n";
  std::size_t done = 0;
  while (done < s.size()) {
    const ssize_t n = write(STDOUT_FILENO, s.data() + done, s.size() - done);
    if (n <= 0) std::_Exit(4);
    done += static_cast<std::size_t>(n);
  }
}

int fail(const std::string& what, const synbench::db::Error& e) {
  std::fprintf(stderr, "db_crash_child: %s: %s\n", what.c_str(), e.message.c_str());
  return 3;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace synbench::db;
  if (argc != 3) {
    std::fprintf(stderr, "usage: db_crash_child <database> <total_points>\n");
    return 2;
  }
  const std::int64_t total = std::atoll(argv[2]);
  auto store = Store::open(argv[1]);
  if (!store) return fail("open", store.error());

  auto sweeps = store->list_sweeps();
  if (!sweeps) return fail("list_sweeps", sweeps.error());
  std::int64_t id = 0;
  if (sweeps->empty()) {
    SweepMeta meta;
    meta.name = "crash-test";
    meta.plan = {{"kind", "synthetic"}, {"points", total}};
    meta.bench_config = {{"bench", "twin"}};
    meta.total_points = total;
    auto created = store->create_sweep(meta);
    if (!created) return fail("create_sweep", created.error());
    id = *created;
  } else {
    id = sweeps->front().id;
  }
  if (auto s = store->set_sweep_state(id, SweepState::running); !s) return fail("set running", s.error());

  auto missing = store->missing_indices(id);
  if (!missing) return fail("missing_indices", missing.error());
  say("resume " + std::to_string(missing->empty() ? -1 : missing->front()));
  for (const std::int64_t index : *missing) {
    if (auto s = store->insert_point(id, index, testing::sample_record(index)); !s)
      return fail("insert_point " + std::to_string(index), s.error());
    say(std::to_string(index));
  }
  if (auto s = store->set_sweep_state(id, SweepState::completed); !s) return fail("set completed", s.error());
  say("done");
  return 0;
}
