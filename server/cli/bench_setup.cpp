// Buses, clock and profile devices from a bench config.
#include "server/cli/bench_setup.hpp"

#include "drivers/bus/modbus_bus.hpp"
#include "drivers/real_time_clock.hpp"
#include "emulator/modbus/twin_register_bus.hpp"
#include "emulator/modbus/twin_service.hpp"
#include "server/cli/args.hpp"
#include "server/http/bench_backend.hpp"

namespace synbench::cli {

ConfiguredBench::ConfiguredBench(const drivers::BenchConfig& config, drivers::BenchProfiles profiles,
                                 const emulator::TwinConfig& twin)
    : config_(config),
      profile_names_{profiles.synrm_drive.name, profiles.load_drive.name, profiles.vfc_meter.name} {
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
  options.retry.max_retries = config.retries;
  options.retry.budget_s = config.retry_budget_ms / 1000.0;
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

nlohmann::json ConfiguredBench::describe_devices() const {
  nlohmann::json out = nlohmann::json::array();
  const std::pair<const char*, const drivers::DeviceConfig*> devices[] = {
      {"synrm", &config_.synrm_drive}, {"load", &config_.load_drive}, {"meter", &config_.vfc_meter}};
  const char* kinds[] = {"synrm_drive", "load_drive", "vfc_meter"};
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& d = *devices[i].second;
    const auto& link = config_.links.at(d.link);
    const bool twin = link.transport == drivers::LinkTransport::twin;
    out.push_back({{"role", devices[i].first},
                   {"kind", kinds[i]},
                   {"backend", twin ? "twin-registers" : "modbus"},
                   {"link", buses_.at(d.link)->name()},
                   {"profile", profile_names_[i]},
                   {"profile_file", d.profile.string()}});
  }
  return out;
}

std::string ConfiguredBench::link_errors() const {
  std::string s;
  for (const auto& [name, bus] : buses_)
    if (!bus->last_error().empty()) s += "  " + bus->last_error() + "\n";
  return s;
}

LoadedBench load_bench_or_throw(const std::string& file, const std::string& flag) {
  drivers::BenchConfigResult r = drivers::load_bench_config(file);
  std::vector<drivers::ProfileError> errors = r.errors;
  std::optional<drivers::BenchProfiles> profiles;
  if (r.config) profiles = drivers::load_bench_profiles(*r.config, errors);
  if (!errors.empty() || !profiles) {
    std::string what;
    for (const auto& e : errors) what += (what.empty() ? "" : "; ") + e.path + ": " + e.reason;
    throw UsageError(flag, file + ": " + what);
  }
  return {std::move(*r.config), std::move(*profiles)};
}

namespace {

class ConfiguredBackend final : public http::BenchBackend {
 public:
  ConfiguredBackend(LoadedBench b, const emulator::TwinConfig& twin, double b1)
      : bench_(b.config, std::move(b.profiles), twin), b1_(b1) {}
  drivers::BenchDevices devices() override { return bench_.bench().devices(); }
  drivers::Clock& clock() override { return bench_.bench().clock(); }
  void tick(double now_s) override { bench_.bench().tick(now_s); }
  nlohmann::json describe() const override { return bench_.describe_devices(); }
  double load_b1_Nms_per_rad() const override { return b1_; }

 private:
  ConfiguredBench bench_;
  double b1_;
};

}  // namespace

std::unique_ptr<http::BenchBackend> make_configured_backend(LoadedBench bench, const emulator::TwinConfig& twin,
                                                            double load_b1_Nms_per_rad) {
  return std::make_unique<ConfiguredBackend>(std::move(bench), twin, load_b1_Nms_per_rad);
}

}  // namespace synbench::cli
