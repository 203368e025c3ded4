// The twin served over real Modbus in the test process: TwinService on its real-time thread,
// the TCP (port chosen by the system) or RTU server with its fault hooks, and a libmodbus bus.
#pragma once

#include <gtest/gtest.h>

#include <memory>

#include "drivers/bus/modbus_bus.hpp"
#include "emulator/modbus/rtu_server.hpp"
#include "emulator/modbus/tcp_server.hpp"
#include "emulator/modbus/twin_service.hpp"
#include "tests/drivers/bus/socat_pair.hpp"
#include "tests/drivers/default_profiles.hpp"

namespace synbench::testing {

struct Emulator {
  explicit Emulator(const emulator::FaultPlan& plan = {}, double time_scale = 1.0)
      : Emulator(default_profiles(), plan, time_scale) {}
  // The twin served through other profiles (one of each kind).
  explicit Emulator(std::vector<drivers::DeviceProfile> served, const emulator::FaultPlan& plan = {},
                    double time_scale = 1.0)
      : profiles(std::move(served)), service(emulator::TwinConfig{}, profiles), faults(plan), tcp(service, faults),
        rtu(service, faults) {
    service.start_realtime(time_scale);
  }
  ~Emulator() {
    tcp.stop();
    rtu.stop();
    service.stop();
  }
  std::uint16_t start_tcp() {
    std::string error;
    EXPECT_TRUE(tcp.start("127.0.0.1", 0, error)) << error;
    return tcp.port();
  }
  bool start_rtu(const std::string& device) {
    std::string error;
    emulator::SerialSettings s;
    s.device = device;
    const bool ok = rtu.start(s, error);
    EXPECT_TRUE(ok) << error;
    return ok;
  }

  std::vector<drivers::DeviceProfile> profiles;
  emulator::TwinService service;
  emulator::FaultInjector faults;
  emulator::ModbusTcpServer tcp;
  emulator::ModbusRtuServer rtu;
};

inline drivers::ModbusLinkOptions link_options(double timeout_s) {
  drivers::ModbusLinkOptions o;
  o.response_timeout_s = timeout_s;
  o.byte_timeout_s = timeout_s;
  o.rtu_quiet_s = timeout_s;
  o.reconnect_initial_s = 0.05;
  o.reconnect_max_s = 1.0;
  return o;
}

}  // namespace synbench::testing
