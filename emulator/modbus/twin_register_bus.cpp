// PDU encoding and reply checking of the in-process bus.
#include "emulator/modbus/twin_register_bus.hpp"

#include "drivers/error.hpp"
#include "emulator/modbus/modbus_pdu.hpp"

namespace synbench::emulator {

using drivers::RegisterKind;
using namespace modbus;

std::error_code TwinRegisterBus::transact(std::uint8_t unit_id, std::span<const std::uint8_t> request,
                                          std::size_t reply_length) {
  ++stats_.transactions;
  const std::size_t n = service_.handle(unit_id, request, std::span(reply_, kMaxPdu));
  if (n == 2 && reply_[0] == (request[0] | 0x80)) {
    ++stats_.exceptions;
    last_exception_code_ = reply_[1];
    ++stats_.exceptions_by_code[reply_[1] < 12 ? reply_[1] : 0];
    last_error_ = "twin unit " + std::to_string(unit_id) + " function " + std::to_string(request[0]) +
                  ": exception " + std::to_string(reply_[1]);
    return make_error_code(errc::exception_reply);
  }
  if (n != reply_length || reply_[0] != request[0]) {
    ++stats_.protocol_errors;
    last_error_ = "twin unit " + std::to_string(unit_id) + ": malformed reply";
    return make_error_code(errc::protocol);
  }
  ++stats_.ok;
  return {};
}

std::error_code TwinRegisterBus::read_bits(std::uint8_t unit_id, RegisterKind kind, std::uint16_t address,
                                           std::span<std::uint8_t> out) {
  if (auto ec = drivers::check_read_bits(kind, address, out.size())) return ec;
  std::uint8_t req[5] = {kind == RegisterKind::coil ? kReadCoils : kReadDiscreteInputs};
  put16(&req[1], address);
  put16(&req[3], static_cast<std::uint16_t>(out.size()));
  const std::size_t bytes = (out.size() + 7) / 8;
  if (auto ec = transact(unit_id, req, 2 + bytes)) return ec;
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = (reply_[2 + i / 8] >> (i % 8)) & 1;
  return {};
}

std::error_code TwinRegisterBus::read_registers(std::uint8_t unit_id, RegisterKind kind, std::uint16_t address,
                                                std::span<std::uint16_t> out) {
  if (auto ec = drivers::check_read_registers(kind, address, out.size())) return ec;
  std::uint8_t req[5] = {kind == RegisterKind::holding ? kReadHoldingRegisters : kReadInputRegisters};
  put16(&req[1], address);
  put16(&req[3], static_cast<std::uint16_t>(out.size()));
  if (auto ec = transact(unit_id, req, 2 + 2 * out.size())) return ec;
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = get16(&reply_[2 + 2 * i]);
  return {};
}

std::error_code TwinRegisterBus::write_bits(std::uint8_t unit_id, std::uint16_t address,
                                            std::span<const std::uint8_t> bits) {
  if (auto ec = drivers::check_write_bits(address, bits.size())) return ec;
  std::uint8_t req[6 + 246] = {kWriteMultipleCoils};
  put16(&req[1], address);
  put16(&req[3], static_cast<std::uint16_t>(bits.size()));
  const std::size_t bytes = (bits.size() + 7) / 8;
  req[5] = static_cast<std::uint8_t>(bytes);
  for (std::size_t i = 0; i < bytes; ++i) req[6 + i] = 0;
  for (std::size_t i = 0; i < bits.size(); ++i)
    if (bits[i]) req[6 + i / 8] = static_cast<std::uint8_t>(req[6 + i / 8] | (1u << (i % 8)));
  return transact(unit_id, std::span<const std::uint8_t>(req, 6 + bytes), 5);
}

std::error_code TwinRegisterBus::write_registers(std::uint8_t unit_id, std::uint16_t address,
                                                 std::span<const std::uint16_t> words) {
  if (auto ec = drivers::check_write_registers(address, words.size())) return ec;
  std::uint8_t req[6 + 246] = {kWriteMultipleRegisters};
  put16(&req[1], address);
  put16(&req[3], static_cast<std::uint16_t>(words.size()));
  req[5] = static_cast<std::uint8_t>(2 * words.size());
  for (std::size_t i = 0; i < words.size(); ++i) put16(&req[6 + 2 * i], words[i]);
  return transact(unit_id, std::span<const std::uint8_t>(req, 6 + 2 * words.size()), 5);
}

}  // namespace synbench::emulator
