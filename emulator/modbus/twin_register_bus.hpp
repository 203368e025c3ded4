// The in-process twin behind the RegisterBus seam: requests are encoded as Modbus PDUs and
// answered by the same RegisterServer that `synbench emulate` puts on the wire, minus the
// transport; and the virtual clock whose waiting advances that twin. With them the profile
// devices run against the twin as fast as the CPU allows.
#pragma once

#include <string>

#include "drivers/bus/register_bus.hpp"
#include "drivers/clock.hpp"
#include "emulator/modbus/twin_service.hpp"

namespace synbench::emulator {

class TwinRegisterBus final : public drivers::RegisterBus {
 public:
  explicit TwinRegisterBus(TwinService& service) : service_(service) {}

  std::error_code read_bits(std::uint8_t unit_id, drivers::RegisterKind kind, std::uint16_t address,
                            std::span<std::uint8_t> out) override;
  std::error_code read_registers(std::uint8_t unit_id, drivers::RegisterKind kind, std::uint16_t address,
                                 std::span<std::uint16_t> out) override;
  std::error_code write_bits(std::uint8_t unit_id, std::uint16_t address, std::span<const std::uint8_t> bits) override;
  std::error_code write_registers(std::uint8_t unit_id, std::uint16_t address,
                                  std::span<const std::uint16_t> words) override;
  drivers::BusStats stats() const override { return stats_; }
  std::string last_error() const override { return last_error_; }
  int last_exception_code() const override { return last_exception_code_; }
  std::string name() const override { return "twin (in-process)"; }

 private:
  // Sends `request`, checks the reply's function code and length; the reply is in reply_.
  std::error_code transact(std::uint8_t unit_id, std::span<const std::uint8_t> request, std::size_t reply_length);

  TwinService& service_;
  drivers::BusStats stats_;
  std::string last_error_;
  int last_exception_code_ = 0;
  std::uint8_t reply_[256];
};

// Virtual time on a TwinService: waiting runs the twin.
class TwinServiceClock final : public drivers::Clock {
 public:
  explicit TwinServiceClock(TwinService& service) : service_(service) {}
  double now_s() const override { return service_.time_s(); }
  void wait_until(double t_s) override { service_.advance_to(t_s); }

 private:
  TwinService& service_;
};

}  // namespace synbench::emulator
