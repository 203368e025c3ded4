// Buses, clock and profile devices from a bench config.
#include "server/cli/bench_setup.hpp"

#include "db/bench_identity.hpp"

#include <algorithm>

#include "drivers/bus/modbus_bus.hpp"
#include "drivers/real_time_clock.hpp"
#include "emulator/modbus/twin_register_bus.hpp"
#include "emulator/modbus/twin_service.hpp"
#include "server/cli/args.hpp"
#include "app/bench_backend.hpp"
#include "emulator/twin_bench.hpp"

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

synbench::Json ConfiguredBench::describe_devices() const {
  synbench::Json out = synbench::Json::array();
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
  // A reply that arrived but could not be read as the profile says: signal, register, raw words.
  if (bench_)
    for (const drivers::ProfileDevice* d : {static_cast<const drivers::ProfileDevice*>(&bench_->synrm()),
                                            static_cast<const drivers::ProfileDevice*>(&bench_->load()),
                                            static_cast<const drivers::ProfileDevice*>(&bench_->meter())})
      if (!d->device_error().empty()) s += "  " + d->device_error() + "\n";
  return s;
}

LoadedBench load_bench_or_throw(const std::string& file, const std::string& flag) {
  drivers::BenchConfigResult r = drivers::load_bench_config(file);
  std::vector<drivers::ProfileError> errors = r.errors;
  std::optional<drivers::BenchProfiles> profiles;
  if (r.config) profiles = drivers::load_bench_profiles(*r.config, errors);
  if (!errors.empty() || !profiles) {
    std::string what;
    for (const auto& e : errors) what += (what.empty() ? "" : "; ") + (e.pointer.empty() ? e.reason : e.pointer + ": " + e.reason);
    // A file that could not be read or parsed is named by the reader's own "FILE: reason".
    const bool names_file = !r.config && errors.size() == 1 && errors.front().reason.rfind(file + ": ", 0) == 0;
    throw UsageError(flag, names_file ? what : file + ": " + what);
  }
  return {std::move(*r.config), std::move(*profiles)};
}

app::BenchDescription twin_description(const emulator::TwinConfig& twin) {
  app::BenchDescription d;
  // The supervisor's bus limits move with the bus, as the firmware's trips do (scale_bus_to).
  const double bus_ratio = twin.dc_bus.source_V / emulator::TwinConfig{}.dc_bus.source_V;
  d.limits.max_udc_V *= bus_ratio;
  d.limits.min_udc_V *= bus_ratio;
  d.max_speed_rpm = twin.firmware.max_speed_rpm;
  // The load drive's own current limit, as torque.
  d.max_load_Nm = 1.5 * twin.load.pole_pairs * twin.load.psi_pm_Wb * twin.load.current_limit_A;
  d.load_b1_Nms_per_rad = twin.load.b1_Nms_per_rad;
  return d;
}

app::BenchDescription bench_description(const drivers::BenchConfig& config) {
  app::BenchDescription d;
  const auto& l = config.limits;
  if (l.max_speed_rpm) d.limits.max_speed_rpm = *l.max_speed_rpm;
  if (l.max_current_A) d.limits.max_current_A = *l.max_current_A;
  if (l.max_udc_V) d.limits.max_udc_V = *l.max_udc_V;
  if (l.min_udc_V) d.limits.min_udc_V = *l.min_udc_V;
  if (l.max_temp_C) d.limits.max_temp_C = *l.max_temp_C;
  if (l.link_timeout_ms) d.limits.link_timeout_s = *l.link_timeout_ms / 1000;
  // An operator's speed stays below the supervisor's trip.
  d.max_speed_rpm = config.setpoints.max_speed_rpm.value_or(std::min(d.max_speed_rpm, d.limits.max_speed_rpm));
  if (config.setpoints.max_load_Nm) d.max_load_Nm = *config.setpoints.max_load_Nm;
  if (config.calibration.load_b1_Nms_per_rad) d.load_b1_Nms_per_rad = *config.calibration.load_b1_Nms_per_rad;
  d.uncertainty = config.uncertainty;
  d.poll_period_s = config.poll_period_ms / 1000;
  return d;
}

namespace {

class ConfiguredBackend final : public app::BenchBackend {
 public:
  ConfiguredBackend(LoadedBench b, const emulator::TwinConfig& twin)
      : description_(b.config.on_twin() ? twin_description(twin) : bench_description(b.config)),
        bench_(b.config, std::move(b.profiles), twin) {
    if (b.config.on_twin()) description_.poll_period_s = b.config.poll_period_ms / 1000;
    const drivers::DeviceProfile& synrm = bench_.bench().synrm().profile();
    if (!synrm.find("temp_C")) description_.synrm_without_temperature = synrm.name;
  }
  drivers::BenchDevices devices() override { return bench_.bench().devices(); }
  drivers::Clock& clock() override { return bench_.bench().clock(); }
  void tick(double now_s) override { bench_.bench().tick(now_s); }
  bool ticks_pending() const override { return bench_.bench().resets_pending(); }
  void set_heartbeats(bool on) override { bench_.bench().set_heartbeats(on); }
  bool heartbeats() const override { return bench_.bench().heartbeats(); }
  synbench::Json describe() const override { return bench_.describe_devices(); }
  const app::BenchDescription& description() const override { return description_; }
  std::string link_errors() const override { return bench_.link_errors(); }
  std::string links() const override { return bench_.describe(); }

 private:
  app::BenchDescription description_;
  ConfiguredBench bench_;
};

// The in-process twin (emulator::TwinBench), its virtual clock advanced by whoever waits on it.
class TwinBackend final : public app::BenchBackend {
 public:
  explicit TwinBackend(const emulator::TwinConfig& config) : twin_(config), description_(twin_description(config)) {}
  drivers::BenchDevices devices() override { return twin_.devices(); }
  drivers::Clock& clock() override { return twin_.clock(); }
  synbench::Json describe() const override {
    const auto dev = [](const char* role, const char* kind) {
      return synbench::Json{{"role", role}, {"kind", kind}, {"backend", "twin"}, {"link", "in-process"}, {"profile", nullptr}};
    };
    return synbench::Json::array({dev("synrm", "synrm_drive"), dev("load", "load_drive"), dev("meter", "vfc_meter"),
                                  dev("trigger", "window_trigger"), dev("truth", "truth_probe")});
  }
  const app::BenchDescription& description() const override { return description_; }

 private:
  emulator::TwinBench twin_;
  app::BenchDescription description_;
};

}  // namespace

std::unique_ptr<app::BenchBackend> make_backend(std::optional<LoadedBench> bench, const emulator::TwinConfig& twin) {
  if (bench) return std::make_unique<ConfiguredBackend>(std::move(*bench), twin);
  return std::make_unique<TwinBackend>(twin);
}

db::BenchIdentity bench_identity(const std::optional<LoadedBench>& bench, const std::string& name) {
  db::BenchIdentity id;
  id.name = name;
  if (!bench) {
    id.devices = db::twin_devices();
    return id;
  }
  using drivers::DeviceKind;
  for (const auto& [kind, device] : {std::pair{DeviceKind::synrm_drive, "synrm_drive"},
                                     std::pair{DeviceKind::load_drive, "load_drive"},
                                     std::pair{DeviceKind::vfc_meter, "vfc_meter"}}) {
    const auto& file = bench->config.device(kind).profile;
    auto d = db::device_identity(device, file);
    id.devices.push_back(d ? std::move(*d) : db::DeviceIdentity{device, file.string(), "unreadable"});
  }
  return id;
}

}  // namespace synbench::cli
