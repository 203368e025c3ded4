// Sockets, MBAP framing and fault hooks of the twin's Modbus TCP server.
#include "emulator/modbus/tcp_server.hpp"

#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>

#include "emulator/modbus/modbus_pdu.hpp"

namespace synbench::emulator {
namespace {

constexpr int kPollMs = 20;  // how quickly the threads notice stop() and link cuts

void sleep_s(double s, const std::atomic<bool>& stop) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(s);
  while (!stop && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

bool send_all(int fd, const std::uint8_t* p, std::size_t n) {
  while (n > 0) {
    const ssize_t k = ::send(fd, p, n, MSG_NOSIGNAL);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) return false;
    p += k;
    n -= static_cast<std::size_t>(k);
  }
  return true;
}

}  // namespace

ModbusTcpServer::~ModbusTcpServer() { stop(); }

bool ModbusTcpServer::listen_on(std::string& error) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* found = nullptr;
  if (const int rc = ::getaddrinfo(host_.c_str(), std::to_string(port_).c_str(), &hints, &found); rc != 0) {
    error = "cannot resolve '" + host_ + "': " + gai_strerror(rc);
    return false;
  }
  error = "no address for '" + host_ + "'";
  for (addrinfo* a = found; a; a = a->ai_next) {
    const int fd = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;
    const int one = 1;
    ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (::bind(fd, a->ai_addr, a->ai_addrlen) == 0 && ::listen(fd, 16) == 0) {
      sockaddr_storage bound{};
      socklen_t len = sizeof bound;
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&bound), &len);
      port_ = ntohs(bound.ss_family == AF_INET6 ? reinterpret_cast<sockaddr_in6*>(&bound)->sin6_port
                                                : reinterpret_cast<sockaddr_in*>(&bound)->sin_port);
      listen_fd_ = fd;
      ::freeaddrinfo(found);
      error.clear();
      return true;
    }
    error = "cannot listen on " + host_ + ":" + std::to_string(port_) + ": " + std::strerror(errno);
    ::close(fd);
  }
  ::freeaddrinfo(found);
  return false;
}

bool ModbusTcpServer::start(const std::string& host, std::uint16_t port, std::string& error) {
  host_ = host;
  port_ = port;
  stop_ = false;
  if (!listen_on(error)) return false;
  acceptor_ = std::thread([this] { accept_loop(); });
  return true;
}

void ModbusTcpServer::stop() {
  stop_ = true;
  if (acceptor_.joinable()) acceptor_.join();
  if (listen_fd_ >= 0) ::close(listen_fd_);
  listen_fd_ = -1;
  close_clients();
  std::list<Client> all;
  {
    std::lock_guard lock(clients_mutex_);
    all.splice(all.begin(), clients_);  // the nodes (and the threads' references) stay put
  }
  for (Client& c : all)
    if (c.thread.joinable()) c.thread.join();
}

void ModbusTcpServer::close_clients() {
  std::lock_guard lock(clients_mutex_);
  // shutdown() wakes the client's thread; the thread closes its own descriptor.
  for (Client& c : clients_)
    if (!c.done) ::shutdown(c.fd, SHUT_RDWR);
}

void ModbusTcpServer::accept_loop() {
  while (!stop_) {
    if (faults_.link_cut()) {
      if (listen_fd_ >= 0) {
        ::close(listen_fd_);
        listen_fd_ = -1;
        close_clients();
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(kPollMs));
      continue;
    }
    if (listen_fd_ < 0) {
      std::string error;
      if (!listen_on(error)) {
        std::this_thread::sleep_for(std::chrono::milliseconds(kPollMs));
        continue;
      }
    }
    {
      // Reap finished connections.
      std::lock_guard lock(clients_mutex_);
      for (auto it = clients_.begin(); it != clients_.end();) {
        if (it->done) {
          it->thread.join();
          it = clients_.erase(it);
        } else {
          ++it;
        }
      }
    }
    pollfd p{listen_fd_, POLLIN, 0};
    if (::poll(&p, 1, kPollMs) <= 0 || !(p.revents & POLLIN)) continue;
    const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (fd < 0) continue;
    const int one = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    std::lock_guard lock(clients_mutex_);
    Client& c = clients_.emplace_back();
    c.fd = fd;
    c.thread = std::thread([this, &c] { serve(c); });
  }
}

bool ModbusTcpServer::read_exact(int fd, std::uint8_t* p, std::size_t n) {
  while (n > 0) {
    if (stop_) return false;
    pollfd q{fd, POLLIN, 0};
    const int rc = ::poll(&q, 1, kPollMs);
    if (rc == 0) continue;
    if (rc < 0 && errno == EINTR) continue;
    if (rc < 0) return false;
    const ssize_t k = ::recv(fd, p, n, 0);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) return false;
    p += k;
    n -= static_cast<std::size_t>(k);
  }
  return true;
}

void ModbusTcpServer::serve(Client& client) {
  const int fd = client.fd;
  std::uint8_t frame[7 + modbus::kMaxPdu];
  std::uint8_t reply[7 + modbus::kMaxPdu];
  while (!stop_) {
    if (!read_exact(fd, frame, 7)) break;
    const std::uint16_t length = modbus::get16(&frame[4]);
    // Not Modbus: a protocol id other than 0 or a length no PDU has. Drop the connection.
    if (modbus::get16(&frame[2]) != 0 || length < 2 || length > 1 + modbus::kMaxPdu) break;
    if (!read_exact(fd, frame + 7, length - 1u)) break;
    if (faults_.link_cut()) {
      faults_.count_ignored_during_cut();
      continue;
    }
    const std::uint8_t unit = frame[6];
    const std::span<const std::uint8_t> pdu(frame + 7, length - 1u);
    const std::span<std::uint8_t> out(reply + 7, modbus::kMaxPdu);
    std::size_t n = 0;
    FaultAction action = FaultAction::none;
    if (unit != 0 && !service_.serves(unit)) {
      // What a gateway answers for a unit behind it that does not respond.
      n = modbus::exception_reply(pdu[0], modbus::kGatewayTargetFailed, out);
    } else {
      action = unit == 0 ? FaultAction::none : faults_.decide();
      n = action == FaultAction::exception ? modbus::exception_reply(pdu[0], modbus::kServerDeviceFailure, out)
                                           : service_.handle(unit, pdu, out);
    }
    if (n == 0 || action == FaultAction::drop) continue;
    if (action == FaultAction::delay) sleep_s(faults_.plan().delay_s, stop_);
    std::uint16_t tid = modbus::get16(&frame[0]);
    if (action == FaultAction::corrupt) tid = static_cast<std::uint16_t>(tid ^ 0x8001);
    modbus::put16(&reply[0], tid);
    modbus::put16(&reply[2], 0);
    modbus::put16(&reply[4], static_cast<std::uint16_t>(n + 1));
    reply[6] = unit;
    if (!send_all(fd, reply, 7 + n)) break;
  }
  // Under the lock, so close_clients() never shuts down a descriptor already reused.
  std::lock_guard lock(clients_mutex_);
  ::close(fd);
  client.done = true;
}

}  // namespace synbench::emulator
