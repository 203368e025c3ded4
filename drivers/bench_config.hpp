// A bench config: which device profile describes each of the bench's three devices and over
// which link the bench reaches it (the in-process twin, Modbus TCP or Modbus RTU), with the
// link's timeouts. `synbench point --bench FILE` reads it; docs/bench-config.md is its schema.
#pragma once

#include "drivers/uncertainty_config.hpp"
#include "drivers/json_fwd.hpp"

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "drivers/bus/modbus_bus.hpp"
#include "drivers/profile/device_profile.hpp"

namespace synbench::drivers {

enum class LinkTransport { twin, tcp, rtu };

struct LinkConfig {
  LinkTransport transport = LinkTransport::tcp;
  TcpEndpoint tcp;
  RtuPort rtu;
  ModbusLinkOptions options;
};

struct DeviceConfig {
  std::filesystem::path profile;        // resolved against the config file's folder
  std::string link;                     // a key of BenchConfig::links
  std::optional<std::uint8_t> unit_id;  // replaces the profile's unit id
};

// What the bench itself allows and how it is calibrated, for real drives (the twin's come from
// its config). Each key is optional; the application fills in its defaults.
struct BenchLimitsConfig {
  std::optional<double> max_speed_rpm, max_current_A, max_udc_V, min_udc_V, max_temp_C, link_timeout_ms;
};
struct BenchSetpointsConfig {
  std::optional<double> max_speed_rpm, max_load_Nm;
};
struct BenchCalibrationConfig {
  std::optional<double> load_b1_Nms_per_rad;
};

struct BenchConfig {
  double time_scale = 1.0;      // bench seconds per wall second; match `synbench emulate --time-scale`
  double poll_period_ms = 10;   // how often the bench reads telemetry
  double window_margin_s = 5;   // wait for a window's results this long past its end
  int retries = 3;              // at most this many repeats of a failed read or idempotent write
  double retry_budget_ms = 250; // and none started later than this after the first attempt (bench time)
  std::map<std::string, LinkConfig> links;
  DeviceConfig synrm_drive, load_drive, vfc_meter;
  BenchLimitsConfig limits;            // the safety supervisor's trips
  BenchSetpointsConfig setpoints;      // what an operator may command
  BenchCalibrationConfig calibration;
  UncertaintyConfig uncertainty;       // a point's type B budget inputs; defaults where not given

  const DeviceConfig& device(DeviceKind k) const;
  // Whether the devices run on the in-process twin (all of them, or none: a config that
  // mixes the twin with real links is rejected).
  bool on_twin() const;
};

struct BenchConfigResult {
  std::optional<BenchConfig> config;  // set exactly when errors is empty
  std::vector<ProfileError> errors;   // JSON pointer and reason, as for profiles
};

// `base_dir` resolves relative profile paths.
BenchConfigResult parse_bench_config(const synbench::Json& doc, const std::filesystem::path& base_dir);
BenchConfigResult load_bench_config(const std::filesystem::path& file);

// The three profiles a config names, with unit id overrides applied. Profile problems are
// reported with the device's pointer ("/devices/vfc_meter/profile") and the profile's own.
struct BenchProfiles {
  DeviceProfile synrm_drive, load_drive, vfc_meter;
};
std::optional<BenchProfiles> load_bench_profiles(const BenchConfig& config, std::vector<ProfileError>& errors);

// Moves every signal at the device's unit id to `unit_id` (signals at another unit stay).
void override_unit_id(DeviceProfile& profile, std::uint8_t unit_id);

}  // namespace synbench::drivers
