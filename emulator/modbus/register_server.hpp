// A Modbus register server generated from device profiles: each profile's signals become
// entries of the four tables of their unit id, values come from a SignalProvider and are
// encoded exactly as the profile says (the drivers decode them with the same codec). One server
// answers all unit ids of its profiles, as `synbench emulate` serves the drive, the load drive
// and the meter on one port. Not thread-safe: the owner serializes requests (TwinService).
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <span>
#include <string_view>
#include <system_error>
#include <vector>

#include "drivers/profile/device_profile.hpp"
#include "emulator/modbus/signal_provider.hpp"

namespace synbench::emulator {

class RegisterServer {
 public:
  RegisterServer(std::vector<drivers::DeviceProfile> profiles, SignalProvider& provider);

  // Answers one request PDU for `unit_id` into `reply` (at least modbus::kMaxPdu bytes) and
  // returns the reply's length: 0 when no reply is due (unit id 0, broadcast: writes are applied
  // on every unit that maps the addresses, and nothing is answered).
  std::size_t handle(std::uint8_t unit_id, std::span<const std::uint8_t> request, std::span<std::uint8_t> reply);
  bool serves(std::uint8_t unit_id) const;

  // Test hook: the signal keeps the value it has at its next read (a stuck sensor or a frozen
  // firmware task). errc::not_supported when no profile of that unit id maps it.
  std::error_code stick(std::uint8_t unit_id, std::string_view signal);
  void unstick_all();

  const std::vector<drivers::DeviceProfile>& profiles() const { return profiles_; }

 private:
  struct Entry {
    const drivers::ProfileSignal* signal = nullptr;
    drivers::DeviceKind device = drivers::DeviceKind::synrm_drive;
    bool stuck = false;
    std::optional<std::array<std::uint16_t, 2>> stuck_words;  // or the bit in [0]
    std::vector<std::optional<double>> served;  // an enumerated signal's device number per code (served_codes.hpp)
    // An array signal is served as one entry per value, each on its own address (a copy of
    // the signal in elements_ without a count): the value's index, or -1 for a single value.
    int element = -1;
  };
  using Table = std::vector<Entry>;  // sorted by address
  using TableKey = std::pair<std::uint8_t, drivers::RegisterKind>;

  Table* table(std::uint8_t unit_id, drivers::RegisterKind kind);
  std::uint8_t read(std::uint8_t unit_id, drivers::RegisterKind kind, std::uint16_t address,
                    std::uint16_t count, std::span<std::uint8_t> data);
  std::uint8_t write_bits(std::uint8_t unit_id, std::uint16_t address, std::span<const std::uint8_t> bits);
  std::uint8_t write_words(std::uint8_t unit_id, std::uint16_t address, std::span<const std::uint16_t> words);
  // The entry's current raw words (or bit in [0]), from the provider or frozen. A masked
  // entry's word has only its own bits set: the register is the OR of its entries.
  std::array<std::uint16_t, 2> raw(Entry& e);
  // The holding register's masked signals a write of `word` changes, as (entry, bench value);
  // kIllegalDataValue when a changed field carries no valid value.
  std::uint8_t split_masked(std::vector<Entry*>& at, std::uint16_t word,
                            std::vector<std::pair<Entry*, double>>& writes);

  std::vector<drivers::DeviceProfile> profiles_;
  SignalProvider& provider_;
  std::map<TableKey, Table> tables_;
  std::deque<drivers::ProfileSignal> elements_;  // the array values' entries' signals (stable addresses)
};

}  // namespace synbench::emulator
