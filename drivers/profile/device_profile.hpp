// A device profile: the data that maps the bench's logical signals of one device to Modbus
// registers, so a user brings a drive by writing JSON rather than code. docs/device-profile.md
// is the schema for those users; parse_device_profile is its one implementation.
#pragma once

#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/profile/register_codec.hpp"
#include "drivers/profile/signal_catalogue.hpp"

namespace synbench::drivers {

// The four Modbus tables.
enum class RegisterKind { coil, discrete_input, holding, input };
enum class Access { r, w, rw };

std::string_view name(RegisterKind k);
std::string_view name(Access a);
std::optional<RegisterKind> parse_register_kind(std::string_view s);
std::optional<Access> parse_access(std::string_view s);

constexpr bool is_bit_kind(RegisterKind k) { return k == RegisterKind::coil || k == RegisterKind::discrete_input; }
// Modbus can write coils and holding registers only.
constexpr bool is_writable_kind(RegisterKind k) { return k == RegisterKind::coil || k == RegisterKind::holding; }

// Watchdog timing carried by the heartbeat signal.
struct HeartbeatTiming {
  std::uint32_t period_ms = 0;   // how often the bench writes a new value
  std::uint32_t timeout_ms = 0;  // how long the device waits for a change before it trips
};

// The device's number for one of the bench's labels of an enumerated signal (state,
// estimator, ...): how a drive with its own codes is translated to the bench's.
struct EnumValue {
  std::int64_t value = 0;
  std::string label;
};

struct ProfileSignal {
  std::string name;
  SignalRole role = SignalRole::telemetry;
  std::uint8_t unit_id = 1;
  RegisterKind kind = RegisterKind::holding;
  std::uint16_t address = 0;
  RegisterEncoding encoding;  // type boolean for coils and discrete inputs; limits ±inf if absent
  std::string unit;           // engineering unit, as in the signal's name; empty if dimensionless
  Access access = Access::r;
  std::vector<EnumValue> values;             // sorted by value; empty: the bench's own codes
  std::optional<HeartbeatTiming> heartbeat;  // set on the heartbeat signal only

  bool readable() const { return access != Access::w; }
  bool writable() const { return access != Access::r; }
  // Last address the signal occupies.
  std::uint16_t last_address() const {
    return static_cast<std::uint16_t>(address + address_width(encoding.type) - 1);
  }
};

// What a vfc_meter profile measures a window with (top-level "meter"): synbench's gated VFC
// counter, free-running counters read at window open and close, or an instrument's own
// average power.
enum class MeterKind { gate, totalizer, power };

struct DeviceProfile {
  std::string name;
  std::string description;
  DeviceKind kind = DeviceKind::synrm_drive;
  std::uint8_t unit_id = 1;
  std::vector<ProfileSignal> signals;  // ordered by register kind, unit id, address
  // Window and meter (drivers/profile/window_schema.hpp). A drive without window signals, and
  // a power meter, are sampled by the bench every poll_period_ms; a totalizer's gate is
  // d(time_base_ticks) / time_base_Hz and its currents come from f0_Hz and kf_Hz_per_A.
  MeterKind meter = MeterKind::gate;
  std::optional<std::uint32_t> poll_period_ms;
  double time_base_Hz = 0;
  double f0_Hz = 0, kf_Hz_per_A = 0;

  const ProfileSignal* find(std::string_view signal) const;
};

// One validation problem: a JSON pointer into the profile document (RFC 6901, "" for the whole
// document) and what is wrong there.
struct ProfileError {
  std::string path;
  std::string reason;
};

// Every problem is reported, not only the first, so a user fixes a profile in one pass.
struct ProfileParseResult {
  std::optional<DeviceProfile> profile;  // set exactly when errors is empty
  std::vector<ProfileError> errors;
};

ProfileParseResult parse_device_profile(const nlohmann::json& doc);

// Reads and parses a profile file; unreadable files and JSON syntax errors are reported at
// path "" with the file name in the reason.
ProfileParseResult load_device_profile(const std::filesystem::path& file);

// Where the profiles of synbench's own firmware live: $SYNBENCH_PROFILE_DIR when set (an installed
// synbench: share/synbench/profiles), else drivers/profiles/ of the source tree.
std::filesystem::path default_profile_dir();
// default_profile_dir() / "<kind>.json"
std::filesystem::path default_profile_path(DeviceKind kind);

// "a/b~c" -> "a~1b~0c": a signal name as one JSON pointer token.
std::string json_pointer_token(std::string_view key);

}  // namespace synbench::drivers
