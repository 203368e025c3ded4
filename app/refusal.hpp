// Why the bench refused a command, typed: the HTTP edge maps each kind to a status code, the
// command line to an exit status. The message is a sentence for the operator.
#pragma once

#include <string>
#include <string_view>

namespace synbench::app {

enum class Refused {
  tripped,           // the supervisor's trip is latched: reset first
  sweep_running,     // a sweep drives the bench
  bench_in_use,      // the drives are enabled by hand
  bench_enabled,     // the command needs the drives disabled
  stop_in_progress,  // an ordered stop is under way
  drive_running,     // a drive still reads back running after its stop
  not_running,       // no such sweep runs here
  invalid_state,     // the sweep's stored state does not allow it
  device_error,      // a device refused or did not answer
  database,          // the store failed
  queue_full,        // too many commands waiting for the bench thread
  shutting_down,     // the daemon is stopping
};

constexpr std::string_view name(Refused r) {
  switch (r) {
    case Refused::tripped: return "tripped";
    case Refused::sweep_running: return "sweep_running";
    case Refused::bench_in_use: return "bench_in_use";
    case Refused::bench_enabled: return "bench_enabled";
    case Refused::stop_in_progress: return "stop_in_progress";
    case Refused::drive_running: return "drive_running";
    case Refused::not_running: return "not_running";
    case Refused::invalid_state: return "invalid_state";
    case Refused::device_error: return "device_error";
    case Refused::database: return "database";
    case Refused::queue_full: return "queue_full";
    case Refused::shutting_down: return "shutting_down";
  }
  return "refused";
}

struct Refusal {
  Refused code = Refused::invalid_state;
  std::string message;
};

}  // namespace synbench::app
