// An in-memory RegisterBus for tests of the profile devices: four tables per unit id, a log of
// requests, a hook run before each request, and errors injected on demand.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <system_error>
#include <tuple>
#include <utility>
#include <vector>

#include "drivers/bus/register_bus.hpp"
#include "drivers/profile/register_codec.hpp"

namespace synbench::drivers::testing {

class FakeBus final : public RegisterBus {
 public:
  struct Request {
    std::string op;  // "read", "write"
    std::uint8_t unit_id;
    RegisterKind kind;
    std::uint16_t address;
    std::size_t count;
  };

  std::uint16_t& at(std::uint8_t unit, RegisterKind kind, std::uint16_t address) {
    return cells_[{unit, static_cast<int>(kind), address}];
  }
  // Stores an engineering value with the signal's encoding (no limits applied).
  void set(const ProfileSignal& s, double value) {
    if (is_bit_kind(s.kind)) {
      at(s.unit_id, s.kind, s.address) = value != 0;
      return;
    }
    RegisterEncoding e = s.encoding;
    e.min = -1e300;
    e.max = 1e300;
    std::uint16_t w[2];
    const auto ec = encode_registers(e, value, std::span(w, address_width(e.type)));
    if (ec) throw std::runtime_error("cannot encode test value for " + s.name);
    for (std::size_t i = 0; i < address_width(e.type); ++i) at(s.unit_id, s.kind, static_cast<std::uint16_t>(s.address + i)) = w[i];
  }

  std::error_code read_bits(std::uint8_t unit, RegisterKind kind, std::uint16_t address,
                            std::span<std::uint8_t> out) override {
    if (auto ec = begin({"read", unit, kind, address, out.size()})) return ec;
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = static_cast<std::uint8_t>(at(unit, kind, static_cast<std::uint16_t>(address + i)));
    return {};
  }
  std::error_code read_registers(std::uint8_t unit, RegisterKind kind, std::uint16_t address,
                                 std::span<std::uint16_t> out) override {
    if (auto ec = begin({"read", unit, kind, address, out.size()})) return ec;
    for (std::size_t i = 0; i < out.size(); ++i) out[i] = at(unit, kind, static_cast<std::uint16_t>(address + i));
    return {};
  }
  std::error_code write_bits(std::uint8_t unit, std::uint16_t address, std::span<const std::uint8_t> bits) override {
    if (auto ec = begin({"write", unit, RegisterKind::coil, address, bits.size()})) return ec;
    for (std::size_t i = 0; i < bits.size(); ++i) at(unit, RegisterKind::coil, static_cast<std::uint16_t>(address + i)) = bits[i];
    return {};
  }
  std::error_code write_registers(std::uint8_t unit, std::uint16_t address, std::span<const std::uint16_t> words) override {
    if (auto ec = begin({"write", unit, RegisterKind::holding, address, words.size()})) return ec;
    for (std::size_t i = 0; i < words.size(); ++i) at(unit, RegisterKind::holding, static_cast<std::uint16_t>(address + i)) = words[i];
    return {};
  }
  BusStats stats() const override { return {}; }
  std::string last_error() const override { return {}; }
  int last_exception_code() const override { return exception_code; }
  std::string name() const override { return "fake"; }

  std::vector<Request> log;
  std::function<void(const Request&)> before;  // runs before each request is served
  std::error_code fail_next;                   // returned by the next request, once
  int exception_code = 0;                      // what last_exception_code() says

 private:
  std::error_code begin(const Request& r) {
    log.push_back(r);
    if (before) before(r);
    if (fail_next) return std::exchange(fail_next, {});
    return {};
  }
  std::map<std::tuple<std::uint8_t, int, std::uint16_t>, std::uint16_t> cells_;
};

}  // namespace synbench::drivers::testing
