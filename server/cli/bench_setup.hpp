// The bench a command runs on, as an app::BenchBackend: the in-process twin (TwinBench), or a
// bench config's links (one RegisterBus per link, shared by the devices on it), clock (real time,
// scaled to match `synbench emulate --time-scale`, or the in-process twin's register map on
// virtual time) and profile devices. `synbench serve`, `sweep`, `point` and `bench` all build
// theirs here, so the same config means the same bench, limits and calibration everywhere.
#pragma once

#include <map>
#include <optional>

#include "drivers/json.hpp"
#include <memory>
#include <string>

#include "db/types.hpp"
#include "drivers/bench_config.hpp"
#include "drivers/profile_devices/profile_bench.hpp"
#include "emulator/twin_config.hpp"

namespace synbench::emulator {
class TwinService;
}

namespace synbench::app {
class BenchBackend;
struct BenchDescription;
}

namespace synbench::cli {

// A bench config file and the profiles it names, loaded and checked; every problem is reported
// in one UsageError naming `flag` (what `point --bench` and `serve --bench` share).
struct LoadedBench {
  drivers::BenchConfig config;
  drivers::BenchProfiles profiles;
};
LoadedBench load_bench_or_throw(const std::string& file, const std::string& flag);

// The identity every sweep this process stores carries (docs/database.md "Bench identity"):
// `name` (--bench-name; "" = the host name), and the bench config's profiles with their
// versions, or the twin's devices without one. A profile file that cannot be read is named
// by its path with version "unreadable" (it was read moments ago by load_bench_or_throw).
db::BenchIdentity bench_identity(const std::optional<LoadedBench>& bench, const std::string& name);

class ConfiguredBench {
 public:
  // `twin` configures the in-process twin when the config's links are of transport twin.
  ConfiguredBench(const drivers::BenchConfig& config, drivers::BenchProfiles profiles,
                  const emulator::TwinConfig& twin);
  ~ConfiguredBench();
  ConfiguredBench(const ConfiguredBench&) = delete;
  ConfiguredBench& operator=(const ConfiguredBench&) = delete;

  drivers::ProfileBench& bench() { return *bench_; }
  const drivers::ProfileBench& bench() const { return *bench_; }
  // The bus of one of the config's links (`synbench bench check --probe` reads through it).
  drivers::RegisterBus& bus(const std::string& link) { return *buses_.at(link); }
  // "tcp 127.0.0.1:1502", "twin (in-process)", ...: the links, for messages.
  std::string describe() const;
  // The last error of each link that had one, one per line.
  std::string link_errors() const;
  // The devices as GET /api/devices lists them.
  synbench::Json describe_devices() const;

 private:
  drivers::BenchConfig config_;
  std::string profile_names_[3];
  std::unique_ptr<emulator::TwinService> twin_;
  std::map<std::string, std::unique_ptr<drivers::RegisterBus>> buses_;
  std::unique_ptr<drivers::Clock> clock_;
  std::unique_ptr<drivers::ProfileBench> bench_;
};

// The bench of a bench config, or the in-process twin without one. The twin's limits and
// calibration follow its config; a bench config's come from its "limits", "setpoints" and
// "calibration" (docs/bench-config.md), with the supervisor's defaults, never from the twin.
std::unique_ptr<app::BenchBackend> make_backend(std::optional<LoadedBench> bench, const emulator::TwinConfig& twin);
app::BenchDescription twin_description(const emulator::TwinConfig& twin);
app::BenchDescription bench_description(const drivers::BenchConfig& config);

}  // namespace synbench::cli
