// The seam between the Modbus protocol and its transport: read and write bits and registers of
// one unit id. libmodbus RTU, libmodbus TCP and the in-process twin implement it, so the
// profile-driven devices above it run unchanged on hardware, on `synbench emulate` and in-process.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <system_error>

#include "drivers/profile/device_profile.hpp"

namespace synbench::drivers {

// The protocol's own limits on one request (Modbus application protocol 1.1b3, 6.1-6.12).
inline constexpr std::size_t kMaxReadRegisters = 125;
inline constexpr std::size_t kMaxReadBits = 2000;
inline constexpr std::size_t kMaxWriteRegisters = 123;
inline constexpr std::size_t kMaxWriteBits = 1968;

// What became of the transactions of one bus, every failure counted by kind. A transaction is
// one request put on the wire; calls refused while the link is down never reach it.
struct BusStats {
  std::uint64_t transactions = 0;
  std::uint64_t ok = 0;
  std::uint64_t timeouts = 0;         // no reply within the response timeout
  std::uint64_t exceptions = 0;       // the device answered with a Modbus exception
  std::uint64_t protocol_errors = 0;  // bad CRC, mismatched or malformed reply
  std::uint64_t link_errors = 0;      // connection reset or closed, I/O error on the port
  std::uint64_t refused_while_down = 0;  // calls answered errc::disconnected during backoff
  std::uint64_t connect_failures = 0;
  std::uint64_t connects = 0;         // successful (re)connections, the first included
  // Exceptions by code (index = exception code, 1..11; 0 counts codes outside that range).
  std::array<std::uint64_t, 12> exceptions_by_code{};
};

class RegisterBus {
 public:
  virtual ~RegisterBus() = default;
  // `kind` is coil or discrete_input; one byte per bit in `out`, 0 or 1.
  virtual std::error_code read_bits(std::uint8_t unit_id, RegisterKind kind, std::uint16_t address,
                                    std::span<std::uint8_t> out) = 0;
  // `kind` is holding or input.
  virtual std::error_code read_registers(std::uint8_t unit_id, RegisterKind kind,
                                         std::uint16_t address, std::span<std::uint16_t> out) = 0;
  // Coils; one byte per bit, 0 or 1.
  virtual std::error_code write_bits(std::uint8_t unit_id, std::uint16_t address,
                                     std::span<const std::uint8_t> bits) = 0;
  // Holding registers.
  virtual std::error_code write_registers(std::uint8_t unit_id, std::uint16_t address,
                                          std::span<const std::uint16_t> words) = 0;

  virtual BusStats stats() const = 0;
  // The Modbus exception code (1..11) of the last call that returned errc::exception_reply, 0
  // when unknown: whether a refusal is worth repeating depends on it (busy, yes; illegal
  // address, never).
  virtual int last_exception_code() const { return 0; }
  // The last failure in words (link, unit, request and the transport's own message), for logs.
  virtual std::string last_error() const = 0;
  // "tcp 127.0.0.1:1502", "rtu /dev/ttyUSB0", "twin (in-process)".
  virtual std::string name() const = 0;
};

// Checks a request against the protocol's limits and the table kinds each call accepts:
// errc::invalid_argument when it cannot be put on the wire as asked.
std::error_code check_read_bits(RegisterKind kind, std::uint16_t address, std::size_t count);
std::error_code check_read_registers(RegisterKind kind, std::uint16_t address, std::size_t count);
std::error_code check_write_bits(std::uint16_t address, std::size_t count);
std::error_code check_write_registers(std::uint16_t address, std::size_t count);

}  // namespace synbench::drivers
