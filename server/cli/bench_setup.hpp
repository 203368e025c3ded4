// A bench assembled from a bench config: the links (one RegisterBus per link, shared by the
// devices on it), the clock (real time, scaled to match `synbench emulate --time-scale`, or the
// in-process twin's virtual time) and the profile devices. What `synbench point --bench` runs.
#pragma once

#include <map>

#include <nlohmann/json.hpp>
#include <memory>
#include <string>

#include "drivers/bench_config.hpp"
#include "drivers/profile_devices/profile_bench.hpp"
#include "emulator/twin_config.hpp"

namespace synbench::emulator {
class TwinService;
}

namespace synbench::http {
class BenchBackend;
}

namespace synbench::cli {

// A bench config file and the profiles it names, loaded and checked; every problem is reported
// in one UsageError naming `flag` (what `point --bench` and `serve --bench` share).
struct LoadedBench {
  drivers::BenchConfig config;
  drivers::BenchProfiles profiles;
};
LoadedBench load_bench_or_throw(const std::string& file, const std::string& flag);

class ConfiguredBench {
 public:
  // `twin` configures the in-process twin when the config's links are of transport twin.
  ConfiguredBench(const drivers::BenchConfig& config, drivers::BenchProfiles profiles,
                  const emulator::TwinConfig& twin);
  ~ConfiguredBench();
  ConfiguredBench(const ConfiguredBench&) = delete;
  ConfiguredBench& operator=(const ConfiguredBench&) = delete;

  drivers::ProfileBench& bench() { return *bench_; }
  // "tcp 127.0.0.1:1502", "twin (in-process)", ...: the links, for messages.
  std::string describe() const;
  // The last error of each link that had one, one per line.
  std::string link_errors() const;
  // The devices as GET /api/devices lists them.
  nlohmann::json describe_devices() const;

 private:
  drivers::BenchConfig config_;
  std::string profile_names_[3];
  std::unique_ptr<emulator::TwinService> twin_;
  std::map<std::string, std::unique_ptr<drivers::RegisterBus>> buses_;
  std::unique_ptr<drivers::Clock> clock_;
  std::unique_ptr<drivers::ProfileBench> bench_;
};

// The daemon's bench on a bench config: ConfiguredBench behind the runtime's BenchBackend.
// `load_b1_Nms_per_rad`: the load machine's friction the sweep engine uses for shaft power.
std::unique_ptr<http::BenchBackend> make_configured_backend(LoadedBench bench, const emulator::TwinConfig& twin,
                                                            double load_b1_Nms_per_rad);

}  // namespace synbench::cli
