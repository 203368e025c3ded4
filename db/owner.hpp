// Which process drives a sweep. A sweep going `running` records its process (host, pid, and
// the process's start: boot id and start time, so a reused pid is not taken for the owner); a
// daemon starting later tells a sweep left `running` by a crash (owner gone) from one that
// `synbench sweep` on the same file runs right now (owner alive). Linux: reads /proc. Internal
// to db/.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace synbench::db::detail {

struct ProcessOwner {
  std::string host;   // gethostname()
  std::int64_t pid = 0;
  std::string start;  // "<boot id>:<start time in clock ticks since boot>", "" if unknown
};

ProcessOwner this_process();

enum class Liveness {
  alive,    // the recorded process still runs (same host, same boot, same pid and start)
  gone,     // it does not: the pid is free or another process's, the machine restarted, or no
            // owner was recorded (a synbench before schema version 4)
  unknown,  // another host (or container) on the same kernel: not ours to judge
};

Liveness liveness(const std::optional<std::string>& host, const std::optional<std::int64_t>& pid,
                  const std::optional<std::string>& start);

// "pid 1234 on bench-pc", or "an unrecorded process" for a sweep without an owner.
std::string describe_owner(const std::optional<std::string>& host, const std::optional<std::int64_t>& pid);

}  // namespace synbench::db::detail
