// This process's identity and whether a recorded one still runs; see owner.hpp.
#include "db/owner.hpp"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <fstream>
#include <sstream>

namespace synbench::db::detail {
namespace {

std::string first_line(const std::string& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  return line;
}

std::string boot_id() { return first_line("/proc/sys/kernel/random/boot_id"); }

// Field 22 of /proc/PID/stat (starttime), after the command name, which may hold spaces and
// parentheses: counted from the last ')'.
std::string start_ticks(std::int64_t pid) {
  const std::string stat = first_line("/proc/" + std::to_string(pid) + "/stat");
  const auto close = stat.rfind(')');
  if (close == std::string::npos) return {};
  std::istringstream rest(stat.substr(close + 1));
  std::string field;
  for (int i = 3; i <= 22; ++i)  // fields 3 (state) .. 22 (starttime)
    if (!(rest >> field)) return {};
  return field;
}

std::string start_of(std::int64_t pid) {
  const std::string boot = boot_id(), ticks = start_ticks(pid);
  return boot.empty() || ticks.empty() ? std::string() : boot + ":" + ticks;
}

std::string hostname() {
  char buf[HOST_NAME_MAX + 1] = {};
  if (::gethostname(buf, sizeof buf - 1) != 0) return {};
  return buf;
}

}  // namespace

ProcessOwner this_process() {
  const auto pid = static_cast<std::int64_t>(::getpid());
  return {hostname(), pid, start_of(pid)};
}

Liveness liveness(const std::optional<std::string>& host, const std::optional<std::int64_t>& pid,
                  const std::optional<std::string>& start) {
  if (!host || !pid) return Liveness::gone;
  const std::string boot = boot_id();
  const std::string recorded_boot = start ? start->substr(0, start->find(':')) : std::string();
  // Another boot of this kernel, or another machine: nothing of then runs now (and SQLite's WAL
  // is not shared across machines).
  if (!boot.empty() && !recorded_boot.empty() && recorded_boot != boot) return Liveness::gone;
  // The same kernel but another host name: a container beside us, whose pids we cannot see.
  if (*host != hostname()) return Liveness::unknown;
  if (*pid <= 0 || *pid > INT_MAX) return Liveness::gone;
  if (::kill(static_cast<pid_t>(*pid), 0) != 0 && errno == ESRCH) return Liveness::gone;
  // The pid runs: the owner only if it is the same process (pids are reused).
  if (start && !start->empty()) {
    const std::string now = start_of(*pid);
    if (!now.empty() && now != *start) return Liveness::gone;
  }
  return Liveness::alive;
}

std::string describe_owner(const std::optional<std::string>& host, const std::optional<std::int64_t>& pid) {
  if (!host || !pid) return "an unrecorded process (synbench before schema version 4)";
  return "pid " + std::to_string(*pid) + " on " + (host->empty() ? std::string("an unnamed host") : *host);
}

}  // namespace synbench::db::detail
