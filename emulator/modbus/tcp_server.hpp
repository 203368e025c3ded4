// Modbus TCP server of the twin: one listening socket, one thread per connection, the MBAP
// framing around TwinService's PDU server, and the fault hooks. A link cut closes the listening
// socket and every connection until it ends, as a pulled cable or a rebooting gateway would.
#pragma once

#include <atomic>
#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "emulator/modbus/fault_injector.hpp"
#include "emulator/modbus/twin_service.hpp"

namespace synbench::emulator {

class ModbusTcpServer {
 public:
  ModbusTcpServer(TwinService& service, FaultInjector& faults) : service_(service), faults_(faults) {}
  ~ModbusTcpServer();
  ModbusTcpServer(const ModbusTcpServer&) = delete;
  ModbusTcpServer& operator=(const ModbusTcpServer&) = delete;

  // Listens on host:port; port 0 lets the system choose (port() tells which). Returns false
  // with the reason in `error` when it cannot.
  bool start(const std::string& host, std::uint16_t port, std::string& error);
  std::uint16_t port() const { return port_; }
  void stop();

 private:
  struct Client {
    int fd = -1;
    std::atomic<bool> done{false};
    std::thread thread;
  };
  bool listen_on(std::string& error);
  void accept_loop();
  void serve(Client& client);
  void close_clients();
  bool read_exact(int fd, std::uint8_t* p, std::size_t n);

  TwinService& service_;
  FaultInjector& faults_;
  std::string host_;
  std::uint16_t port_ = 0;
  int listen_fd_ = -1;
  std::atomic<bool> stop_{false};
  std::thread acceptor_;
  std::mutex clients_mutex_;
  std::list<Client> clients_;
};

}  // namespace synbench::emulator
