// `synbench emulate`: the bench's twin as a Modbus device (TCP, RTU, or both at once on the same
// twin), in real or scaled time, with the default profiles' register map, the firmware's
// watchdog and windows, and fault hooks for tests.
#include <signal.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <sstream>
#include <thread>

#include "drivers/bench_check.hpp"
#include "drivers/profile/device_profile.hpp"
#include "drivers/profile/number_format.hpp"
#include "drivers/profile/profile_dir.hpp"
#include "emulator/modbus/fault_injector.hpp"
#include "emulator/modbus/rtu_server.hpp"
#include "emulator/modbus/served_codes.hpp"
#include "emulator/modbus/tcp_server.hpp"
#include "emulator/modbus/twin_service.hpp"
#include "emulator/twin_config_schema.hpp"
#include "server/cli/args.hpp"
#include "server/cli/bench_setup.hpp"
#include "server/cli/commands.hpp"
#include "server/cli/profile_problems.hpp"

namespace synbench::cli {

const char* const kEmulateHelp = R"(usage: synbench emulate [--tcp HOST:PORT] [--rtu DEVICE] [options]

Serves the bench's twin over Modbus as synbench's drive firmware would: the SynRM drive at unit
id 1, the load drive at 2 and the VFC meter at 3, with the register maps of the default profiles
(docs/register-map.md), or through other profiles (--profiles, --bench). The drives' watchdog
stops both machines and latches fault 6 when the heartbeat stops changing; the fault_reset
signal clears it; window_start opens a measurement window (shared by the three devices, as one
trigger line). Runs until SIGINT or SIGTERM.

links (at least one; given both, they serve the same twin: a bench on RTU, a test on TCP):
  --tcp HOST:PORT        Modbus TCP; port 0 picks a free port. Prints "listening on tcp HOST:PORT"
  --rtu DEVICE           Modbus RTU on a serial port or pseudo-terminal. Prints "listening on rtu DEVICE"
                         (after the tcp line when both are given)
  --baud N               RTU baud rate (default 115200)
  --parity P             RTU parity: none (default), even, odd

register maps (at most one; default: the default profiles, drivers/profiles/):
  --profiles DIR         the profiles in DIR: every *.json there whose top level has a "kind" is a
                         profile (others are skipped); exactly one synrm_drive, load_drive and
                         vfc_meter profile. Their unit ids, addresses and encodings are served
                         (drives without window signals, a totalizer or power meter too:
                         docs/device-profile.md)
  --bench CONFIG         the three profiles a bench config names, at its unit ids (its links are
                         not used: every device is served on each link given here, so their
                         registers must not collide)
  A drive state a profile's "state" has no number for is served as its "otherwise", else as
  its fallback (stopping as running, faulted as disabled) with a warning at start; one none of
  these can show (running, disabled) is refused, exit 2 (docs/modbus.md)

twin:
  --time-scale X         X seconds of twin time per wall second, 0 < X <= 1000 (default 1);
                         run the bench with the same time_scale (docs/bench-config.md)
  --config FILE          twin config JSON (see docs/emulator-config.md)
  --seed N               noise seed (default from config)
  --udc-V V              DC-bus source voltage, 100..800 V (default 425)
  --temp-C T             winding temperature at start (default 50)
  --watchdog-timeout-ms T  the drives' heartbeat timeout in twin time, 1..600000 (default:
                         the profiles' 500); at --time-scale X the master's scheduling jitter
                         counts X times over, so a scaled CI run may need a longer one
  --duration-s S         exit after S seconds of wall time

fault hooks (for tests; docs/modbus.md; with both links, on both, counted together):
  --fault-delay-pct P    percent of replies sent --fault-delay-ms late (past the master's timeout)
  --fault-delay-ms D     delay of a delayed reply, 1..60000 ms (default 1000)
  --fault-drop-pct P     percent of requests executed but never answered
  --fault-exception-pct P  percent of requests refused with exception 4 (not executed)
  --fault-corrupt-pct P  percent of replies corrupted (RTU: bad CRC; TCP: wrong transaction id)
  --fault-stuck LIST     signals that freeze at their next read: UNIT:SIGNAL[,UNIT:SIGNAL...],
                         e.g. 1:speed_rpm,3:gate_sequence (UNIT: a unit id the profiles serve)
  --fault-cut-s S        on SIGUSR1, cut the link(s) for S seconds (default 2)
  --fault-seed N         seed of the fault draws (default 1)
  --help                 this text

On exit prints the injected faults: "faults: requests N delayed N dropped N exceptions N
corrupted N cuts N ignored_during_cut N".
exit status: 0 stopped, 1 a link could not be opened, 2 bad input
)";

namespace {

std::atomic<bool> g_stop{false};
std::atomic<bool> g_cut{false};

extern "C" void on_stop_signal(int) { g_stop = true; }
extern "C" void on_cut_signal(int) { g_cut = true; }

double percent(const Args& a, const std::string& flag) {
  const double v = a.number(flag).value_or(0.0);
  if (v < 0 || v > 100) throw UsageError(flag, drivers::format_number(v) + " is outside [0, 100] %");
  return v;
}

// "host:port" or "[v6]:port".
void parse_endpoint(const std::string& text, std::string& host, std::uint16_t& port) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == text.size())
    throw UsageError("--tcp", "'" + text + "' is not HOST:PORT");
  host = text.substr(0, colon);
  if (host.size() > 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  const std::string p = text.substr(colon + 1);
  char* end = nullptr;
  const long v = std::strtol(p.c_str(), &end, 10);
  if (end != p.c_str() + p.size() || v < 0 || v > 65535)
    throw UsageError("--tcp", "'" + p + "' is not a port (0..65535)");
  port = static_cast<std::uint16_t>(v);
}

// "FILE: /pointer: reason; ..." for a UsageError.
std::string problems(const std::vector<drivers::FileError>& errors) {
  std::string what;
  for (const auto& e : errors) what += (what.empty() ? "" : "; ") + problem_text(e.file, e.error);
  return what;
}

// Every device is served on every endpoint: registers that collide anywhere collide here.
std::vector<drivers::DeviceProfile> bench_profiles(const std::string& file) {
  LoadedBench b = load_bench_or_throw(file, "--bench");
  std::vector<drivers::FileError> errors;
  for (auto& e : drivers::check_bench(b.config, b.profiles, true)) errors.push_back({file, std::move(e)});
  if (!errors.empty()) throw UsageError("--bench", problems(errors));
  return {std::move(b.profiles.synrm_drive), std::move(b.profiles.load_drive), std::move(b.profiles.vfc_meter)};
}

std::vector<drivers::DeviceProfile> dir_profiles(const std::string& dir) {
  drivers::ProfileDirResult r = drivers::load_profile_dir(dir);
  if (!r.profiles) throw UsageError("--profiles", problems(r.errors));
  const auto& p = *r.profiles;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j)
      if (const auto hit = drivers::register_collision(p[i], p[j]))
        r.errors.push_back({r.files[j].string(), {"", *hit + ": the profiles are served on one endpoint"}});
  if (!r.errors.empty()) throw UsageError("--profiles", problems(r.errors));
  return std::move(*r.profiles);
}

std::vector<drivers::DeviceProfile> default_profiles() {
  std::vector<drivers::DeviceProfile> out;
  for (const drivers::DeviceKind k : drivers::kDeviceKinds) {
    drivers::ProfileParseResult r = drivers::load_device_profile(drivers::default_profile_path(k));
    if (!r.profile) throw std::runtime_error("default profile " + drivers::default_profile_path(k).string() +
                                             " does not parse: " + r.errors.front().reason);
    out.push_back(std::move(*r.profile));
  }
  return out;
}

}  // namespace

int emulate_command(const std::vector<std::string>& argv) {
  emulator::TwinConfig config;
  emulator::FaultPlan faults;
  std::string tcp_host, rtu_device;
  std::uint16_t tcp_port = 0;
  emulator::SerialSettings serial;
  double time_scale = 1, cut_s = 2;
  std::optional<double> duration_s, watchdog_s;
  std::vector<std::pair<int, std::string>> stuck;
  std::vector<drivers::DeviceProfile> profiles;
  std::string profiles_option = "--profiles";  // what to name when the profiles are refused
  try {
    Args a(argv, {"--help"},
           {"--tcp", "--rtu", "--baud", "--parity", "--time-scale", "--config", "--seed", "--udc-V", "--temp-C",
            "--duration-s", "--watchdog-timeout-ms", "--profiles", "--bench", "--fault-delay-pct", "--fault-delay-ms", "--fault-drop-pct", "--fault-exception-pct",
            "--fault-corrupt-pct", "--fault-stuck", "--fault-cut-s", "--fault-seed"});
    if (a.has("--help")) {
      std::cout << kEmulateHelp;
      return 0;
    }
    if (!a.positional().empty()) throw UsageError(a.positional().front(), "unexpected argument");
    const auto tcp = a.text("--tcp");
    const auto rtu = a.text("--rtu");
    if (!tcp && !rtu) throw UsageError("--tcp", "a link is required: --tcp HOST:PORT or --rtu DEVICE");
    if (tcp) parse_endpoint(*tcp, tcp_host, tcp_port);
    if (rtu) {
      if (rtu->empty()) throw UsageError("--rtu", "needs a device");
      serial.device = *rtu;
    } else {
      for (const char* f : {"--baud", "--parity"})
        if (a.text(f)) throw UsageError(f, "applies to --rtu only");
    }
    if (auto b = a.number("--baud")) {
      unsigned speed = 0;
      if (*b != std::floor(*b) || !emulator::baud_constant(static_cast<int>(*b), speed))
        throw UsageError("--baud", drivers::format_number(*b) + " is not a supported baud rate (1200..921600)");
      serial.baud = static_cast<int>(*b);
    }
    if (auto p = a.text("--parity")) {
      if (*p == "none") serial.parity = 'N';
      else if (*p == "even") serial.parity = 'E';
      else if (*p == "odd") serial.parity = 'O';
      else throw UsageError("--parity", "'" + *p + "' is not a parity (none, even, odd)");
    }
    time_scale = a.number("--time-scale").value_or(1.0);
    if (!(time_scale > 0) || time_scale > 1000)
      throw UsageError("--time-scale", drivers::format_number(time_scale) + " is outside (0, 1000]");
    if (auto file = a.text("--config")) config = emulator::load_twin_config_file(*file);
    const auto dir = a.text("--profiles");
    const auto bench = a.text("--bench");
    if (dir && bench) throw UsageError("--profiles", "give --profiles or --bench, not both");
    if (dir) profiles = dir_profiles(*dir);
    if (bench) profiles = bench_profiles(*bench);
    if (bench) profiles_option = "--bench";
    if (auto seed = a.number("--seed")) {
      if (*seed < 0 || *seed > 2147483647 || *seed != std::floor(*seed))
        throw UsageError("--seed", "must be a whole number in [0, 2147483647]");
      config.sim.seed_int = static_cast<int>(*seed);
    }
    if (auto udc = a.number("--udc-V")) {
      if (*udc < 100 || *udc > 800) throw UsageError("--udc-V", drivers::format_number(*udc) + " is outside [100, 800] V");
      config.scale_bus_to(*udc);
    }
    if (auto t = a.number("--temp-C")) {
      if (*t < -40 || *t >= config.firmware.overtemp_trip_C)
        throw UsageError("--temp-C", drivers::format_number(*t) + " is outside [-40, " + drivers::format_number(config.firmware.overtemp_trip_C) + ") degC");
      config.thermal.initial_C = *t;
    }
    if (auto d = a.number("--duration-s")) {
      if (!(*d > 0)) throw UsageError("--duration-s", drivers::format_number(*d) + " must be positive");
      duration_s = *d;
    }
    if (auto ms = a.number("--watchdog-timeout-ms")) {
      if (*ms < 1 || *ms > 600000)
        throw UsageError("--watchdog-timeout-ms", drivers::format_number(*ms) + " is outside [1, 600000] ms");
      watchdog_s = *ms / 1000;
    }
    faults.delay_pct = percent(a, "--fault-delay-pct");
    faults.drop_pct = percent(a, "--fault-drop-pct");
    faults.exception_pct = percent(a, "--fault-exception-pct");
    faults.corrupt_pct = percent(a, "--fault-corrupt-pct");
    if (faults.delay_pct + faults.drop_pct + faults.exception_pct + faults.corrupt_pct > 100)
      throw UsageError("--fault-delay-pct", "the fault percentages add up to more than 100");
    if (auto ms = a.number("--fault-delay-ms")) {
      if (*ms < 1 || *ms > 60000) throw UsageError("--fault-delay-ms", drivers::format_number(*ms) + " is outside [1, 60000] ms");
      faults.delay_s = *ms / 1000;
    }
    if (auto s = a.number("--fault-cut-s")) {
      if (!(*s > 0) || *s > 3600) throw UsageError("--fault-cut-s", drivers::format_number(*s) + " is outside (0, 3600] s");
      cut_s = *s;
    }
    if (auto seed = a.number("--fault-seed")) {
      if (*seed < 0 || *seed > 4294967295.0 || *seed != std::floor(*seed))
        throw UsageError("--fault-seed", "must be a whole number in [0, 4294967295]");
      faults.seed = static_cast<std::uint32_t>(*seed);
    }
    if (auto list = a.text("--fault-stuck")) {
      std::stringstream ss(*list);
      std::string item;
      while (std::getline(ss, item, ',')) {
        const auto colon = item.find(':');
        const std::string unit = colon == std::string::npos ? "" : item.substr(0, colon);
        char* end = nullptr;
        const long id = std::strtol(unit.c_str(), &end, 10);
        if (unit.empty() || end != unit.c_str() + unit.size() || id < 1 || id > 247)
          throw UsageError("--fault-stuck", "'" + item + "' is not UNIT:SIGNAL with a unit id 1..247");
        stuck.emplace_back(static_cast<int>(id), item.substr(colon + 1));
      }
    }
  } catch (const UsageError& e) {
    std::cerr << "synbench emulate: " << e.what() << "\n";
    return 2;
  } catch (const emulator::ConfigError& e) {
    std::cerr << "synbench emulate: --config: " << e.what() << "\n";
    return 2;
  }

  if (profiles.empty()) profiles = default_profiles();
  // Said once, at start: a drive state the map cannot show is served as its fallback, or refused.
  const auto notes = emulator::check_served_codes(profiles);
  for (const auto& w : notes.warnings) std::cerr << "synbench emulate: warning: " << w << "\n";
  if (!notes.errors.empty()) {
    for (const auto& e : notes.errors) std::cerr << "synbench emulate: " << profiles_option << ": " << e << "\n";
    return 2;
  }
  // A profile that maps a signal the twin has no value for is refused, naming the device and
  // the signal, rather than served as a register stuck at 0.
  std::unique_ptr<emulator::TwinService> twin;
  try {
    twin = std::make_unique<emulator::TwinService>(config, std::move(profiles));
  } catch (const std::invalid_argument& e) {
    std::cerr << "synbench emulate: " << profiles_option << ": " << e.what() << "\n";
    return 2;
  }
  emulator::TwinService& service = *twin;
  for (const auto& [unit, signal] : stuck) {
    const auto ec = service.locked([&](auto&, auto&, emulator::RegisterServer& server) {
      return server.stick(static_cast<std::uint8_t>(unit), signal);
    });
    if (ec) {
      std::cerr << "synbench emulate: --fault-stuck: unit " << unit << " has no signal '" << signal << "'\n";
      return 2;
    }
  }
  if (watchdog_s)
    service.locked([&](auto&, emulator::TwinSignals& s, auto&) { s.set_watchdog_timeout_s(*watchdog_s); });
  // One injector for both links: its draws and counts are shared (it locks), and a cut
  // silences the device on every link, as a hung firmware would.
  emulator::FaultInjector injector(faults);
  emulator::ModbusTcpServer tcp_server(service, injector);
  emulator::ModbusRtuServer rtu_server(service, injector);
  std::string error;
  if (!tcp_host.empty() && !tcp_server.start(tcp_host, tcp_port, error)) {
    std::cerr << "synbench emulate: --tcp: " << error << "\n";
    return 1;
  }
  if (!serial.device.empty() && !rtu_server.start(serial, error)) {
    std::cerr << "synbench emulate: --rtu: " << error << "\n";
    return 1;
  }

  struct sigaction stop_action{};
  stop_action.sa_handler = on_stop_signal;
  ::sigaction(SIGINT, &stop_action, nullptr);
  ::sigaction(SIGTERM, &stop_action, nullptr);
  struct sigaction cut_action{};
  cut_action.sa_handler = on_cut_signal;
  ::sigaction(SIGUSR1, &cut_action, nullptr);
  ::signal(SIGPIPE, SIG_IGN);

  service.start_realtime(time_scale);
  if (!tcp_host.empty())
    std::cout << "listening on tcp " << tcp_host << ":" << tcp_server.port() << std::endl;
  if (!serial.device.empty()) std::cout << "listening on rtu " << serial.device << std::endl;
  const auto start = std::chrono::steady_clock::now();
  while (!g_stop) {
    if (g_cut.exchange(false)) {
      injector.cut_link(cut_s);
      std::cout << "link cut for " << cut_s << " s" << std::endl;
    }
    if (duration_s && std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > *duration_s)
      break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  tcp_server.stop();
  rtu_server.stop();
  service.stop();
  const emulator::FaultCounts c = injector.counts();
  std::cout << "faults: requests " << c.requests << " delayed " << c.delayed << " dropped " << c.dropped
            << " exceptions " << c.exceptions << " corrupted " << c.corrupted << " cuts " << c.cuts
            << " ignored_during_cut " << c.ignored_during_cut << "\n"
            << "twin time " << service.time_s() << " s, worst lag " << service.max_lag_s() << " s" << std::endl;
  return 0;
}

}  // namespace synbench::cli
