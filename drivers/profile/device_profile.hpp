// A device profile: the data that maps the bench's logical signals of one device to Modbus
// registers, so a user brings a drive by writing JSON rather than code. docs/device-profile.md
// is the schema for those users; parse_device_profile is its one implementation.
#pragma once

#include "drivers/json.hpp"


#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/json_reader.hpp"
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

// How the bench resets a drive's latched fault through the fault_reset signal: level writes 1
// (the device acts on the level and clears the register itself, as synbench's firmware does);
// pulse writes 1, holds it pulse_ms and writes 0, for a device that resets on a rising edge.
struct FaultResetMode {
  enum class Mode { level, pulse };
  Mode mode = Mode::level;
  std::uint32_t pulse_ms = 0;  // pulse only
};

// What keeps a device's watchdog fed: counter (the bench writes a new heartbeat value every
// period_ms), any_write (the bench rewrites the `refresh` command signal's last written value
// every period_ms; the device trips when no write arrives for timeout_ms), none (the device has
// no watchdog; only the bench's own supervisor stops it).
enum class WatchdogKind { counter, any_write, none };
std::string_view name(WatchdogKind k);

struct WatchdogSpec {
  WatchdogKind kind = WatchdogKind::none;
  std::string refresh;           // any_write: the signal rewritten
  std::uint32_t period_ms = 0;   // counter: the heartbeat's; any_write: the refresh period
  std::uint32_t timeout_ms = 0;  // the device's timeout
};

// The device's number for one of the bench's labels of an enumerated signal (state,
// estimator, ...): how a drive with its own codes is translated to the bench's. A label may
// have several numbers; the first listed is the one the bench writes.
struct EnumValue {
  std::int64_t value = 0;
  std::string label;
  bool written = true;  // the label's first listed number: what the bench writes for it
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
  // The bits of a u16 holding or input register the signal occupies ("bit" N is 1 << N); 0:
  // the whole value. Signals on disjoint masks share a register.
  std::uint16_t mask = 0;
  std::string otherwise;        // enumerated: the label of any device number not in values
  FaultResetMode reset;         // fault_reset only

  // An array signal's number of values (their addresses follow one another, each
  // address_width(type) wide); 0 for a single value.
  std::uint8_t count = 0;

  bool masked() const { return mask != 0; }
  // How many values the signal carries: count, or 1.
  std::size_t values_count() const { return count ? count : 1u; }

  bool readable() const { return access != Access::w; }
  bool writable() const { return access != Access::r; }
  // Last address the signal occupies (an array's: its last value's).
  std::uint16_t last_address() const {
    return static_cast<std::uint16_t>(address + address_width(encoding.type) * values_count() - 1);
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
  // Counter when a heartbeat signal is mapped; else as the profile says (a drive must say).
  WatchdogSpec watchdog;
  // A drive's documented stop time (its manual's): how long after its disable it may still read
  // running or stopping, e.g. an SS1-style ramp on the run bit. 0: at once. Drives only.
  std::uint32_t stop_time_ms = 0;

  const ProfileSignal* find(std::string_view signal) const;
};

// One validation problem: a JSON pointer into the profile document and what is wrong there.
using ProfileError = JsonError;

// Every problem is reported, not only the first, so a user fixes a profile in one pass.
struct ProfileParseResult {
  std::optional<DeviceProfile> profile;  // set exactly when errors is empty
  std::vector<ProfileError> errors;
};

ProfileParseResult parse_device_profile(const synbench::Json& doc);

// Reads and parses a profile file; unreadable files and JSON syntax errors are reported at
// path "" with the file name in the reason.
ProfileParseResult load_device_profile(const std::filesystem::path& file);

// Where the profiles of synbench's own firmware live: $SYNBENCH_PROFILE_DIR when set (an installed
// synbench: share/synbench/profiles), else drivers/profiles/ of the source tree.
std::filesystem::path default_profile_dir();
// default_profile_dir() / "<kind>.json"
std::filesystem::path default_profile_path(DeviceKind kind);

}  // namespace synbench::drivers
