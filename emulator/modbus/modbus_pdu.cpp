// CRC and RTU request framing.
#include "emulator/modbus/modbus_pdu.hpp"

namespace synbench::emulator::modbus {

std::uint16_t crc16(std::span<const std::uint8_t> bytes) {
  std::uint16_t crc = 0xFFFF;
  for (const std::uint8_t b : bytes) {
    crc ^= b;
    for (int i = 0; i < 8; ++i) crc = (crc & 1) ? static_cast<std::uint16_t>((crc >> 1) ^ 0xA001) : static_cast<std::uint16_t>(crc >> 1);
  }
  return crc;
}

int rtu_request_length(std::span<const std::uint8_t> frame) {
  if (frame.size() < 2) return 0;
  switch (frame[1]) {
    case kReadCoils:
    case kReadDiscreteInputs:
    case kReadHoldingRegisters:
    case kReadInputRegisters:
    case kWriteSingleCoil:
    case kWriteSingleRegister:
      return 8;  // unit, function, two 16-bit fields, CRC
    case kWriteMultipleCoils:
    case kWriteMultipleRegisters:
      if (frame.size() < 7) return 0;
      return 9 + frame[6];  // unit, function, address, count, byte count, data, CRC
    default:
      return -1;
  }
}

}  // namespace synbench::emulator::modbus
