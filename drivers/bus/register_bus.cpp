// Request checks shared by every RegisterBus implementation.
#include "drivers/bus/register_bus.hpp"

#include "drivers/error.hpp"

namespace synbench::drivers {
namespace {

std::error_code check_span(std::uint16_t address, std::size_t count, std::size_t max) {
  if (count == 0 || count > max || address + count - 1 > 0xFFFF)
    return make_error_code(errc::invalid_argument);
  return {};
}

}  // namespace

std::error_code check_read_bits(RegisterKind kind, std::uint16_t address, std::size_t count) {
  if (!is_bit_kind(kind)) return make_error_code(errc::invalid_argument);
  return check_span(address, count, kMaxReadBits);
}

std::error_code check_read_registers(RegisterKind kind, std::uint16_t address, std::size_t count) {
  if (is_bit_kind(kind)) return make_error_code(errc::invalid_argument);
  return check_span(address, count, kMaxReadRegisters);
}

std::error_code check_write_bits(std::uint16_t address, std::size_t count) {
  return check_span(address, count, kMaxWriteBits);
}

std::error_code check_write_registers(std::uint16_t address, std::size_t count) {
  return check_span(address, count, kMaxWriteRegisters);
}

}  // namespace synbench::drivers
