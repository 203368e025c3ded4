// A bench assembled from a bench config: the links (one RegisterBus per link, shared by the
// devices on it), the clock (real time, scaled to match `synbench emulate --time-scale`, or the
// in-process twin's virtual time) and the profile devices. What `synbench point --bench` runs.
#pragma once

#include <map>
#include <memory>
#include <string>

#include "drivers/bench_config.hpp"
#include "drivers/profile_devices/profile_bench.hpp"
#include "emulator/twin_config.hpp"

namespace synbench::emulator {
class TwinService;
}

namespace synbench::cli {

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

 private:
  std::unique_ptr<emulator::TwinService> twin_;
  std::map<std::string, std::unique_ptr<drivers::RegisterBus>> buses_;
  std::unique_ptr<drivers::Clock> clock_;
  std::unique_ptr<drivers::ProfileBench> bench_;
};

}  // namespace synbench::cli
