// Buses, clock and profile devices from a bench config.
#include "server/cli/bench_setup.hpp"

#include "drivers/bus/modbus_bus.hpp"
#include "drivers/real_time_clock.hpp"
#include "emulator/modbus/twin_register_bus.hpp"
#include "emulator/modbus/twin_service.hpp"

namespace synbench::cli {

ConfiguredBench::ConfiguredBench(const drivers::BenchConfig& config, drivers::BenchProfiles profiles,
                                 const emulator::TwinConfig& twin) {
  using drivers::LinkTransport;
  if (config.on_twin()) {
    // The in-process twin serves the config's own profiles, so a user's profile can be tried
    // against the twin before it meets the hardware.
    twin_ = std::make_unique<emulator::TwinService>(
        twin, std::vector<drivers::DeviceProfile>{profiles.synrm_drive, profiles.load_drive, profiles.vfc_meter});
    clock_ = std::make_unique<emulator::TwinServiceClock>(*twin_);
  } else {
    clock_ = std::make_unique<drivers::RealTimeClock>(config.time_scale);
  }
  for (const auto& [name, link] : config.links) {
    switch (link.transport) {
      case LinkTransport::twin: buses_[name] = std::make_unique<emulator::TwinRegisterBus>(*twin_); break;
      case LinkTransport::tcp: buses_[name] = std::make_unique<drivers::ModbusTcpBus>(link.tcp, link.options); break;
      case LinkTransport::rtu: buses_[name] = std::make_unique<drivers::ModbusRtuBus>(link.rtu, link.options); break;
    }
  }
  drivers::ProfileBenchOptions options;
  options.window_margin_s = config.window_margin_s;
  options.retries = config.retries;
  bench_ = std::make_unique<drivers::ProfileBench>(
      *buses_.at(config.synrm_drive.link), std::move(profiles.synrm_drive), *buses_.at(config.load_drive.link),
      std::move(profiles.load_drive), *buses_.at(config.vfc_meter.link), std::move(profiles.vfc_meter), *clock_,
      options);
}

ConfiguredBench::~ConfiguredBench() = default;

std::string ConfiguredBench::describe() const {
  std::string s;
  for (const auto& [name, bus] : buses_) s += (s.empty() ? "" : ", ") + bus->name();
  return s;
}

std::string ConfiguredBench::link_errors() const {
  std::string s;
  for (const auto& [name, bus] : buses_)
    if (!bus->last_error().empty()) s += "  " + bus->last_error() + "\n";
  return s;
}

}  // namespace synbench::cli
