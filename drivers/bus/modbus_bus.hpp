// RegisterBus over libmodbus: Modbus TCP and Modbus RTU. libmodbus's own error recovery is off
// (it can block for seconds); instead each failure is mapped once (modbus_errors.hpp), counted,
// and recovered here within bounded time:
//  - timeout or malformed reply on TCP: the connection is closed and the next request opens a
//    fresh one, so a late reply can never be taken for the answer to a later request;
//  - timeout or malformed reply on RTU (no transaction ids on a serial line): the port's input is
//    flushed and the line drained until it has been quiet for `rtu_quiet_s`;
//  - link failure (reset, refused, I/O error): closed, and reconnected with bounded exponential
//    backoff; calls during the backoff fail at once with errc::disconnected.
// A bus is owned by one thread: the first thread that uses it; a call from another thread is
// refused (errc::busy), as a libmodbus context must never be shared.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "drivers/bus/backoff.hpp"
#include "drivers/bus/register_bus.hpp"

struct _modbus;  // libmodbus's context; its header stays out of ours

namespace synbench::drivers {

struct ModbusLinkOptions {
  double response_timeout_s = 0.2;  // from the end of the request to the first byte of the reply
  double byte_timeout_s = 0.05;     // between bytes of one reply
  double reconnect_initial_s = 0.05;
  double reconnect_max_s = 1.0;
  double rtu_quiet_s = 0.2;         // RTU: line silence that ends the drain after a timeout
};

struct TcpEndpoint {
  std::string host = "127.0.0.1";
  std::uint16_t port = 502;
};

struct RtuPort {
  std::string device;
  int baud = 115200;
  char parity = 'N';  // 'N', 'E' or 'O'
  int data_bits = 8;
  int stop_bits = 1;
};

class ModbusBus : public RegisterBus {
 public:
  // A configured context, not yet connected, or why libmodbus could not make one.
  struct NewContext {
    _modbus* ctx = nullptr;
    std::string error;
  };
  ~ModbusBus() override;
  ModbusBus(const ModbusBus&) = delete;
  ModbusBus& operator=(const ModbusBus&) = delete;

  std::error_code read_bits(std::uint8_t unit_id, RegisterKind kind, std::uint16_t address,
                            std::span<std::uint8_t> out) override;
  std::error_code read_registers(std::uint8_t unit_id, RegisterKind kind, std::uint16_t address,
                                 std::span<std::uint16_t> out) override;
  std::error_code write_bits(std::uint8_t unit_id, std::uint16_t address,
                             std::span<const std::uint8_t> bits) override;
  std::error_code write_registers(std::uint8_t unit_id, std::uint16_t address,
                                  std::span<const std::uint16_t> words) override;
  BusStats stats() const override;
  int last_exception_code() const override { return last_exception_code_; }
  std::string last_error() const override;
  std::string name() const override { return name_; }

  // Opens the link now rather than on the first request.
  std::error_code connect();
  bool connected() const { return connected_; }

 protected:
  ModbusBus(std::string name, const ModbusLinkOptions& options, NewContext context);
  _modbus* context() const { return ctx_; }
  const ModbusLinkOptions& options() const { return options_; }
  // Recovery after a timeout or a malformed reply; the link stays usable or is closed.
  virtual void resynchronize() = 0;
  void close_link();

 private:
  struct Request;
  template <class Call>
  std::error_code transact(const Request& r, Call&& call);
  std::error_code ensure_connected();
  std::error_code fail(const Request& r, int err);
  std::error_code refuse(const std::string& why);
  static double now_s();

  std::string name_;
  ModbusLinkOptions options_;
  _modbus* ctx_ = nullptr;
  std::string create_error_;
  bool connected_ = false;
  Backoff backoff_;
  std::thread::id owner_;
  mutable std::mutex stats_mutex_;  // stats may be read from another thread
  BusStats stats_;
  std::string last_error_;
  int last_exception_code_ = 0;  // owner thread only
};

class ModbusTcpBus final : public ModbusBus {
 public:
  ModbusTcpBus(const TcpEndpoint& endpoint, const ModbusLinkOptions& options = {});

 private:
  void resynchronize() override;
};

class ModbusRtuBus final : public ModbusBus {
 public:
  ModbusRtuBus(const RtuPort& port, const ModbusLinkOptions& options = {});

 private:
  void resynchronize() override;
};

}  // namespace synbench::drivers
