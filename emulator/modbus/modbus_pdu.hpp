// Modbus PDUs as bytes (function code first), without a transport: what the twin's register
// server reads and answers, and what the in-process bus sends it. The TCP and RTU servers only
// add their framing (MBAP header; unit id and CRC).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace synbench::emulator::modbus {

enum Function : std::uint8_t {
  kReadCoils = 0x01,
  kReadDiscreteInputs = 0x02,
  kReadHoldingRegisters = 0x03,
  kReadInputRegisters = 0x04,
  kWriteSingleCoil = 0x05,
  kWriteSingleRegister = 0x06,
  kWriteMultipleCoils = 0x0F,
  kWriteMultipleRegisters = 0x10,
};

enum Exception : std::uint8_t {
  kIllegalFunction = 0x01,
  kIllegalDataAddress = 0x02,
  kIllegalDataValue = 0x03,
  kServerDeviceFailure = 0x04,
  kServerDeviceBusy = 0x06,
  kGatewayTargetFailed = 0x0B,
};

// The longest PDU (Modbus application protocol 1.1b3, 4.1): 253 bytes.
inline constexpr std::size_t kMaxPdu = 253;

inline std::uint16_t get16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>((p[0] << 8) | p[1]);
}
inline void put16(std::uint8_t* p, std::uint16_t v) {
  p[0] = static_cast<std::uint8_t>(v >> 8);
  p[1] = static_cast<std::uint8_t>(v & 0xFF);
}

// Writes an exception reply to `request_function` into `reply`; returns its length (2).
inline std::size_t exception_reply(std::uint8_t request_function, std::uint8_t code, std::span<std::uint8_t> reply) {
  reply[0] = static_cast<std::uint8_t>(request_function | 0x80);
  reply[1] = code;
  return 2;
}

// CRC-16/MODBUS of an RTU frame (polynomial 0xA001 reflected, initial 0xFFFF); sent low byte first.
std::uint16_t crc16(std::span<const std::uint8_t> bytes);

// Length of the RTU request frame (unit id, PDU, CRC) that starts with `frame`: 0 while more
// bytes are needed to tell, -1 for a function code the server does not implement.
int rtu_request_length(std::span<const std::uint8_t> frame);

}  // namespace synbench::emulator::modbus
