// Modbus RTU server of the twin on a serial port (or one end of a pseudo-terminal pair): the
// unit ids of the twin's profiles on one line, frames delimited by their function code's
// length and checked by CRC (a frame with a bad CRC is discarded and the line resynchronized on
// silence, as a slave must), broadcast writes to unit 0, and the fault hooks. Requests for
// other unit ids are ignored: they belong to other devices on the line.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>

#include "emulator/modbus/fault_injector.hpp"
#include "emulator/modbus/twin_service.hpp"

namespace synbench::emulator {

struct SerialSettings {
  std::string device;
  int baud = 115200;
  char parity = 'N';  // 'N', 'E', 'O'
  int data_bits = 8;
  int stop_bits = 1;
};

struct RtuServerStats {
  std::uint64_t frames = 0, crc_errors = 0, discarded_bytes = 0;
};

class ModbusRtuServer {
 public:
  ModbusRtuServer(TwinService& service, FaultInjector& faults) : service_(service), faults_(faults) {}
  ~ModbusRtuServer();
  ModbusRtuServer(const ModbusRtuServer&) = delete;
  ModbusRtuServer& operator=(const ModbusRtuServer&) = delete;

  bool start(const SerialSettings& settings, std::string& error);
  void stop();
  RtuServerStats stats() const;

 private:
  void loop();
  void answer(std::uint8_t* frame, std::size_t length);

  TwinService& service_;
  FaultInjector& faults_;
  int fd_ = -1;
  double silence_s_ = 0.005;  // gap that ends a garbled frame
  std::atomic<bool> stop_{false};
  std::thread thread_;
  std::atomic<std::uint64_t> frames_{0}, crc_errors_{0}, discarded_{0};
};

// The termios speed for a baud rate; false for a rate the system does not know.
bool baud_constant(int baud, unsigned& speed);

}  // namespace synbench::emulator
