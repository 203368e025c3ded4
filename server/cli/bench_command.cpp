// `synbench bench`: a bench config and its drives from the command line, without the daemon:
// `check` validates it and probes its devices (bench_check_command.cpp),
// `status` reads both drives back, `reset` clears their latched faults (after an E-stop or a
// watchdog trip) once it has seen that neither runs.
#include <cstdio>
#include <iostream>

#include "drivers/json.hpp"

#include "app/bench_backend.hpp"
#include "app/supervised_point.hpp"
#include "bench/safety_supervisor.hpp"
#include "server/cli/args.hpp"
#include "server/cli/bench_setup.hpp"
#include "server/cli/commands.hpp"

namespace synbench::cli {

const char* const kBenchHelp = R"(usage: synbench bench check CONFIG [--probe] [--json]
       synbench bench status --bench FILE [--json]
       synbench bench reset --bench FILE [--json]

A bench config (docs/bench-config.md) and its devices from the command line, without the daemon.

  check    validates the config and the profiles it names: every problem as
           "FILE: /json/pointer: reason" (a profile's own problems name the profile file after
           the device's pointer), and what shows only when they are put together (two devices
           on one link with the same unit id and overlapping registers, one serial port named by
           two links). It also lists the SynRM drive's telemetry values whose register
           steps are coarser than a running drive's noise, which the supervisor's
           frozen-telemetry check therefore cannot watch (--json: "frozen_check_unwatched").
           With --probe, connects over the config's links and reads every readable
           signal of every device once (reads only, never a write), printing device, signal,
           table, address(es), unit id, raw registers (hex) and the decoded value and unit, or
           the signal's error. Exit 0 when valid (and, probing, every signal read), 1 otherwise
  status   reads both drives back: state, fault, speed, current, DC bus
  reset    clears the drives' latched faults (an E-stop's, a watchdog's), then reads them back.
           Sends the watchdog heartbeat first, so a drive's watchdog does not trip again at
           once. Refused while a drive reports running: it never starts anything

options:
  --bench FILE   bench config JSON (required for status and reset; check takes it either way)
  --probe        check: read every readable signal of every device once
  --json         one JSON object instead of the readable listing
  --help         this text

exit status: 0 done (reset: both drives fault-free), 1 a drive could not be read, still
faulted, or runs, 2 bad input
)";

namespace {


synbench::Json drives_json(const bench::SafetySupervisor& s) {
  synbench::Json j;
  if (const auto& t = s.synrm())
    j["synrm"] = {{"state", drivers::state_name(t->state)}, {"fault", std::string(drivers::fault_name(t->fault))},
                  {"speed_rpm", t->speed_rpm}, {"im_A", t->im_A}, {"udc_V", t->udc_V}};
  else
    j["synrm"] = nullptr;
  if (const auto& t = s.load())
    j["load"] = {{"state", drivers::state_name(t->state)}, {"fault", std::string(drivers::fault_name(t->fault))},
                 {"torque_Nm", t->torque_Nm}};
  else
    j["load"] = nullptr;
  return j;
}

void print(const synbench::Json& j, bool json) {
  if (json) {
    std::cout << j.dump() << "\n";
    return;
  }
  for (const char* role : {"synrm", "load"}) {
    const auto& d = j[role];
    std::cout << (std::string(role) == "synrm" ? "SynRM drive: " : "load drive:  ");
    if (d.is_null()) {
      std::cout << "cannot be read\n";
      continue;
    }
    std::cout << d["state"].get<std::string>() << ", fault " << d["fault"].get<std::string>();
    if (d.contains("speed_rpm")) std::printf(", %.0f rpm, %.2f A, %.0f V", d["speed_rpm"].get<double>(), d["im_A"].get<double>(), d["udc_V"].get<double>());
    if (d.contains("torque_Nm")) std::printf(", %.2f N m", d["torque_Nm"].get<double>());
    std::cout << "\n";
  }
}

bool readable(const bench::SafetySupervisor& s) { return s.synrm() && s.load(); }
bool running(const bench::SafetySupervisor& s) {
  return (s.synrm() && drivers::running(s.synrm()->state)) || (s.load() && drivers::running(s.load()->state));
}
bool faulted(const bench::SafetySupervisor& s) {
  return (s.synrm() && s.synrm()->fault != drivers::Fault::none) || (s.load() && s.load()->fault != drivers::Fault::none);
}

}  // namespace

int bench_command(const std::vector<std::string>& argv) {
  if (!argv.empty() && argv[0] == "check") return bench_check_command({argv.begin() + 1, argv.end()});
  std::optional<LoadedBench> loaded;
  std::string action;
  bool json = false;
  try {
    Args a(argv, {"--json", "--help"}, {"--bench"});
    if (a.has("--help")) {
      std::cout << kBenchHelp;
      return 0;
    }
    if (a.positional().size() != 1 || (a.positional()[0] != "status" && a.positional()[0] != "reset"))
      throw UsageError("ACTION", "give check, status or reset");
    action = a.positional()[0];
    json = a.has("--json");
    const auto file = a.text("--bench");
    if (!file) throw UsageError("--bench", "is required");
    loaded = load_bench_or_throw(*file, "--bench");
  } catch (const UsageError& e) {
    std::cerr << "synbench bench: " << e.what() << "\n";
    return 2;
  }
  auto backend = make_backend(std::move(loaded), emulator::TwinConfig{});
  bench::SafetySupervisor supervisor(backend->devices(), backend->description().limits);
  const double tick_s = backend->description().poll_period_s;
  double t = backend->clock().now_s();
  backend->tick(t);  // a heartbeat: a reset must not be undone by the watchdog at once
  supervisor.tick(t);
  if (!readable(supervisor)) {
    print(drives_json(supervisor), json);
    std::cerr << "synbench bench: cannot read the drives:\n" << backend->link_errors();
    return 1;
  }
  if (action == "status") {
    print(drives_json(supervisor), json);
    return 0;
  }
  if (running(supervisor)) {
    print(drives_json(supervisor), json);
    std::cerr << "synbench bench: reset refused: a drive reports running (stop it through whoever runs it)\n";
    return 1;
  }
  const auto dev = backend->devices();
  std::error_code ec;
  if ((ec = dev.synrm->reset_fault()) || (ec = dev.load->reset_fault())) {
    std::cerr << "synbench bench: clearing the faults failed: " << ec.message() << "\n" << backend->link_errors();
    return 1;
  }
  // Read back after a period, so the drives have acted on it, and after any reset pulse ended
  // (its hold is at most 60 s).
  const double pulse_deadline_s = t + 61.0;
  do {
    t += tick_s;
    backend->clock().wait_until(t);
    backend->tick(t);
  } while (backend->ticks_pending() && t < pulse_deadline_s);
  supervisor.tick(t);
  print(drives_json(supervisor), json);
  if (!readable(supervisor) || faulted(supervisor)) {
    std::cerr << "synbench bench: a drive still reports a fault after the reset\n";
    return 1;
  }
  return 0;
}

}  // namespace synbench::cli
