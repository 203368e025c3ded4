// libmodbus transports: transactions, error mapping and counting, bounded recovery.
#include "drivers/bus/modbus_bus.hpp"

#include <modbus.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>

#include "drivers/bus/modbus_errors.hpp"
#include "drivers/error.hpp"

namespace synbench::drivers {

struct ModbusBus::Request {
  const char* what;  // "read input", "write coils", ...
  std::uint8_t unit_id;
  std::uint16_t address;
  std::size_t count;
};

namespace {

void split_seconds(double s, std::uint32_t& sec, std::uint32_t& usec) {
  const double us = std::max(1.0, std::round(s * 1e6));
  sec = static_cast<std::uint32_t>(us / 1e6);
  usec = static_cast<std::uint32_t>(us - sec * 1e6);
}

// Settings every context gets, TCP or RTU.
ModbusBus::NewContext configure(modbus_t* ctx, const ModbusLinkOptions& o) {
  if (!ctx) return {nullptr, modbus_strerror(errno)};
  // No built-in recovery: on a link error libmodbus would sleep and reconnect on its own,
  // blocking the caller for up to the response timeout per attempt.
  modbus_set_error_recovery(ctx, MODBUS_ERROR_RECOVERY_NONE);
  std::uint32_t sec, usec;
  split_seconds(o.response_timeout_s, sec, usec);
  modbus_set_response_timeout(ctx, sec, usec);
  split_seconds(std::min(o.byte_timeout_s, o.response_timeout_s), sec, usec);
  modbus_set_byte_timeout(ctx, sec, usec);
  return {ctx, {}};
}

std::string tcp_name(const TcpEndpoint& e) { return "tcp " + e.host + ":" + std::to_string(e.port); }
std::string rtu_name(const RtuPort& p) { return "rtu " + p.device; }

ModbusBus::NewContext new_tcp(const TcpEndpoint& e, const ModbusLinkOptions& o) {
  // The protocol-independent variant resolves host names as well as dotted addresses.
  return configure(modbus_new_tcp_pi(e.host.c_str(), std::to_string(e.port).c_str()), o);
}

ModbusBus::NewContext new_rtu(const RtuPort& p, const ModbusLinkOptions& o) {
  return configure(modbus_new_rtu(p.device.c_str(), p.baud, p.parity, p.data_bits, p.stop_bits), o);
}

}  // namespace

ModbusBus::ModbusBus(std::string name, const ModbusLinkOptions& options, NewContext context)
    : name_(std::move(name)),
      options_(options),
      ctx_(context.ctx),
      create_error_(std::move(context.error)),
      backoff_(options.reconnect_initial_s, options.reconnect_max_s) {}

ModbusBus::~ModbusBus() {
  if (!ctx_) return;
  if (connected_) modbus_close(ctx_);
  modbus_free(ctx_);
}

double ModbusBus::now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

BusStats ModbusBus::stats() const {
  std::lock_guard lock(stats_mutex_);
  return stats_;
}

std::string ModbusBus::last_error() const {
  std::lock_guard lock(stats_mutex_);
  return last_error_;
}

std::error_code ModbusBus::refuse(const std::string& why) {
  std::lock_guard lock(stats_mutex_);
  last_error_ = name_ + ": " + why;
  return make_error_code(errc::invalid_argument);
}

void ModbusBus::close_link() {
  if (connected_) modbus_close(ctx_);
  connected_ = false;
}

std::error_code ModbusBus::connect() {
  if (!ctx_) return refuse("cannot create the libmodbus context: " + create_error_);
  if (connected_) return {};
  if (modbus_connect(ctx_) == -1) {
    const int err = errno;
    backoff_.failed(now_s());
    std::lock_guard lock(stats_mutex_);
    ++stats_.connect_failures;
    last_error_ = name_ + ": connect: " + modbus_error_text(err);
    return make_error_code(errc::disconnected);
  }
  connected_ = true;
  backoff_.succeeded();
  // Whatever a previous connection left in the buffers is not ours.
  modbus_flush(ctx_);
  std::lock_guard lock(stats_mutex_);
  ++stats_.connects;
  return {};
}

std::error_code ModbusBus::ensure_connected() {
  if (connected_) return {};
  if (ctx_ && !backoff_.may_attempt(now_s())) {
    std::lock_guard lock(stats_mutex_);
    ++stats_.refused_while_down;
    return make_error_code(errc::disconnected);
  }
  return connect();
}

std::error_code ModbusBus::fail(const Request& r, int err) {
  const MappedError m = map_modbus_errno(err);
  last_exception_code_ = m.exception_code;
  {
    std::lock_guard lock(stats_mutex_);
    switch (m.fault) {
      case LinkFault::timeout: ++stats_.timeouts; break;
      case LinkFault::exception:
        ++stats_.exceptions;
        ++stats_.exceptions_by_code[m.exception_code < 12 ? m.exception_code : 0];
        break;
      case LinkFault::protocol: ++stats_.protocol_errors; break;
      case LinkFault::link: ++stats_.link_errors; break;
      case LinkFault::invalid: break;
    }
    last_error_ = name_ + " unit " + std::to_string(r.unit_id) + " " + r.what + " " +
                  std::to_string(r.address) + "+" + std::to_string(r.count) + ": " +
                  modbus_error_text(err);
  }
  switch (m.fault) {
    case LinkFault::timeout:
    case LinkFault::protocol: resynchronize(); break;
    case LinkFault::link:
      close_link();
      backoff_.failed(now_s());
      break;
    case LinkFault::exception:
    case LinkFault::invalid: break;
  }
  return m.code;
}

template <class Call>
std::error_code ModbusBus::transact(const Request& r, Call&& call) {
  if (owner_ == std::thread::id{}) owner_ = std::this_thread::get_id();
  if (owner_ != std::this_thread::get_id()) {
    std::lock_guard lock(stats_mutex_);
    last_error_ = name_ + ": used from a second thread; a bus belongs to one thread";
    return make_error_code(errc::busy);
  }
  if (auto ec = ensure_connected()) return ec;
  modbus_set_slave(ctx_, r.unit_id);
  {
    std::lock_guard lock(stats_mutex_);
    ++stats_.transactions;
  }
  errno = 0;
  const int rc = call(ctx_);
  if (rc == static_cast<int>(r.count)) {
    std::lock_guard lock(stats_mutex_);
    ++stats_.ok;
    return {};
  }
  // A short count without an error would be a reply that does not match the request.
  return fail(r, rc < 0 ? errno : EMBBADDATA);
}

std::error_code ModbusBus::read_bits(std::uint8_t unit_id, RegisterKind kind, std::uint16_t address,
                                     std::span<std::uint8_t> out) {
  if (auto ec = check_read_bits(kind, address, out.size())) return ec;
  const bool coils = kind == RegisterKind::coil;
  const int n = static_cast<int>(out.size());
  return transact({coils ? "read coils" : "read discrete inputs", unit_id, address, out.size()},
                  [&](modbus_t* c) {
                    return coils ? modbus_read_bits(c, address, n, out.data())
                                 : modbus_read_input_bits(c, address, n, out.data());
                  });
}

std::error_code ModbusBus::read_registers(std::uint8_t unit_id, RegisterKind kind,
                                          std::uint16_t address, std::span<std::uint16_t> out) {
  if (auto ec = check_read_registers(kind, address, out.size())) return ec;
  const bool holding = kind == RegisterKind::holding;
  const int n = static_cast<int>(out.size());
  return transact({holding ? "read holding" : "read input", unit_id, address, out.size()},
                  [&](modbus_t* c) {
                    return holding ? modbus_read_registers(c, address, n, out.data())
                                   : modbus_read_input_registers(c, address, n, out.data());
                  });
}

std::error_code ModbusBus::write_bits(std::uint8_t unit_id, std::uint16_t address,
                                      std::span<const std::uint8_t> bits) {
  if (auto ec = check_write_bits(address, bits.size())) return ec;
  const int n = static_cast<int>(bits.size());
  return transact({"write coils", unit_id, address, bits.size()}, [&](modbus_t* c) {
    return n == 1 ? modbus_write_bit(c, address, bits[0] ? 1 : 0)
                  : modbus_write_bits(c, address, n, bits.data());
  });
}

std::error_code ModbusBus::write_registers(std::uint8_t unit_id, std::uint16_t address,
                                           std::span<const std::uint16_t> words) {
  if (auto ec = check_write_registers(address, words.size())) return ec;
  const int n = static_cast<int>(words.size());
  return transact({"write holding", unit_id, address, words.size()}, [&](modbus_t* c) {
    return n == 1 ? modbus_write_register(c, address, words[0])
                  : modbus_write_registers(c, address, n, words.data());
  });
}

ModbusTcpBus::ModbusTcpBus(const TcpEndpoint& endpoint, const ModbusLinkOptions& options)
    : ModbusBus(tcp_name(endpoint), options, new_tcp(endpoint, options)) {}

void ModbusTcpBus::resynchronize() {
  // A late reply would still arrive on this connection; a fresh one cannot carry it. The next
  // request reconnects at once (no backoff: the peer is up, it was only slow).
  close_link();
}

ModbusRtuBus::ModbusRtuBus(const RtuPort& port, const ModbusLinkOptions& options)
    : ModbusBus(rtu_name(port), options, new_rtu(port, options)) {}

void ModbusRtuBus::resynchronize() {
  // RTU replies carry no transaction id: a late reply taken for the next one would be a wrong
  // value. Discard what is buffered, then whatever arrives until the line has been quiet.
  // The input only: modbus_flush (TCIOFLUSH) also throws away the request just written while the
  // peer has not taken it yet (a pty's far end, a USB adapter still sending), and a late reply
  // arrives right after a write: that lost a drive's disable on every repeat that met one.
  modbus_t* ctx = context();
  const int fd = modbus_get_socket(ctx);
  if (fd < 0) return;
  ::tcflush(fd, TCIFLUSH);
  const int quiet_ms = std::max(1, static_cast<int>(std::lround(options().rtu_quiet_s * 1000)));
  const auto give_up = std::chrono::steady_clock::now() +
                       std::chrono::duration<double>(4 * options().rtu_quiet_s + 4 * options().response_timeout_s);
  unsigned char junk[256];
  while (std::chrono::steady_clock::now() < give_up) {
    pollfd p{fd, POLLIN, 0};
    const int rc = ::poll(&p, 1, quiet_ms);
    if (rc == 0) return;  // quiet: the line is ours again
    if (rc < 0) {
      if (errno == EINTR) continue;
      return;
    }
    if (p.revents & (POLLERR | POLLHUP | POLLNVAL)) return;
    if (::read(fd, junk, sizeof junk) <= 0) return;
  }
}

}  // namespace synbench::drivers
