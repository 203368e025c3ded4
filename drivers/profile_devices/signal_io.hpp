// A device's signals by name, through a RegisterBus, as its profile maps them. Reads are
// planned once (ReadPlan): the signals of one table and unit id that sit next to each other go
// in one request, so a telemetry read costs a few transactions, not one per signal. Every value
// is decoded with its limits: a register outside them is errc::protocol, never data.
#pragma once

#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "drivers/bus/register_bus.hpp"
#include "drivers/clock.hpp"
#include "drivers/profile/device_profile.hpp"
#include "drivers/profile_devices/retry_policy.hpp"

namespace synbench::drivers {

class ReadPlan {
 public:
  // The named signals the profile maps (others are left out: their values stay NaN).
  ReadPlan(const DeviceProfile& profile, std::initializer_list<std::string_view> names);
  ReadPlan(const DeviceProfile& profile, std::span<const std::string_view> names);

  std::size_t size() const { return slots_.size(); }
  std::size_t requests() const { return requests_.size(); }
  // Whether the profile maps the i-th name.
  bool present(std::size_t i) const { return i < slots_.size() && slots_[i].signal != nullptr; }
  bool present(std::string_view signal) const { return present(index(signal)); }
  // The position of `signal` among the names the plan was made of (size() when not among them).
  std::size_t index(std::string_view signal) const;
  // The device's own number of the i-th signal at the last successful read of this plan, before
  // its enumerated label (NaN when absent or never read): the raw code of an unknown fault.
  double device_value(std::size_t i) const {
    return i < device_values_.size() ? device_values_[i] : std::numeric_limits<double>::quiet_NaN();
  }

 private:
  friend class SignalIo;
  struct Request {
    std::uint8_t unit_id;
    RegisterKind kind;
    std::uint16_t address;
    std::uint16_t count;
    std::size_t buffer_offset;  // into the words (or bits) buffer
  };
  struct Slot {
    const ProfileSignal* signal = nullptr;
    std::size_t request = 0;
    std::size_t offset = 0;  // of the signal's first word (or bit) in its request
  };
  void plan(const DeviceProfile& profile, std::span<const std::string_view> names);

  std::vector<Request> requests_;
  std::vector<Slot> slots_;
  std::vector<std::string> names_;
  std::size_t words_ = 0;  // buffer sizes
  mutable std::vector<double> device_values_;  // of the last successful read
  mutable std::vector<std::uint16_t> last_words_;  // of the last successful read (arrays)
};

class SignalIo {
 public:
  SignalIo(RegisterBus& bus, const DeviceProfile& profile) : bus_(bus), profile_(profile) {}

  // When a failed request is repeated (retry_policy.hpp): reads and idempotent writes only (a
  // window start is never repeated here: done twice it would not mean the same; WindowChannel
  // asks the device instead), within the policy's budget of `clock`'s time. Without a clock
  // only the count bounds the repeats. Default: no repeats.
  void set_retry_policy(const RetryPolicy& policy, const Clock* clock) {
    policy_ = policy;
    clock_ = clock;
  }
  const RetryPolicy& retry_policy() const { return policy_; }
  // Whether a request first attempted at `first_s` (clock time) that failed with `ec` after
  // `repeats` repeats may be made once more.
  bool may_repeat(std::error_code ec, int repeats, double first_s) const;
  double now_s() const { return clock_ ? clock_->now_s() : 0.0; }
  // Repeats made so far (for tests and logs).
  std::uint64_t repeats() const { return repeats_; }

  const DeviceProfile& profile() const { return profile_; }
  RegisterBus& bus() { return bus_; }
  bool has(std::string_view signal) const { return profile_.find(signal) != nullptr; }

  // Values of the plan's signals in engineering units, in the plan's order: bits as 0 or 1,
  // enumerated signals as the bench's codes, NaN for signals the profile does not map.
  // On error `values` is unspecified. A masked signal reads its bits of the register; a fault
  // code is never out of range (a code without a label reads Fault::unknown).
  std::error_code read(const ReadPlan& plan, std::span<double> values);
  // The values of an array signal of the plan (a profile's "count") at the plan's last
  // successful read, in engineering units, element 0 first; read() gives only element 0.
  // errc::not_supported when the profile does not map it; a value outside its limits as read().
  std::error_code read_array(const ReadPlan& plan, std::string_view signal, std::vector<double>& values);
  // Encodes with the signal's limits (errc::invalid_argument outside them) and writes. A masked
  // signal is a read-modify-write of its register: the other signals' bits are kept.
  // errc::not_supported when the profile does not map the signal.
  std::error_code write(std::string_view signal, double value);
  // As write(), one request only, whatever the retry policy (a masked signal's read before it
  // may still be repeated): for a caller that repeats it itself, after other devices had theirs.
  std::error_code write_once(std::string_view signal, double value);
  // The last value written to `signal` (bench units), if any.
  std::optional<double> last_written(std::string_view signal) const;

  // The last failure in the device's terms: device (kind and profile name), signal, table,
  // address, unit id, raw word(s) in hex and the reason; empty when the last call succeeded.
  const std::string& last_error() const { return last_error_; }

 private:
  template <class Request>
  std::error_code with_retries(bool idempotent, Request&& request);
  // Decodes one signal of a completed read; on failure sets last_error_.
  std::error_code decode(const ProfileSignal& s, std::span<const std::uint16_t> words, std::size_t at,
                         double& bench_value, double& device_value);
  std::error_code write(std::string_view signal, double value, bool repeat);
  std::error_code write_masked(const ProfileSignal& s, double device_value, bool idempotent);
  std::error_code fail(std::error_code ec, const ProfileSignal* s, std::string what);
  std::string device() const;

  RegisterBus& bus_;
  const DeviceProfile& profile_;
  RetryPolicy policy_{0.0, 0};
  const Clock* clock_ = nullptr;
  std::uint64_t repeats_ = 0;
  std::vector<std::uint16_t> words_;
  std::vector<std::uint8_t> bits_;
  std::vector<double> device_values_;
  std::vector<std::pair<std::string, double>> written_;
  std::string last_error_;
};

}  // namespace synbench::drivers
