// Serial port setup, RTU framing and fault hooks of the twin's Modbus RTU server.
#include "emulator/modbus/rtu_server.hpp"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <vector>

#include "emulator/modbus/modbus_pdu.hpp"

namespace synbench::emulator {

bool baud_constant(int baud, unsigned& speed) {
  switch (baud) {
    case 1200: speed = B1200; return true;
    case 2400: speed = B2400; return true;
    case 4800: speed = B4800; return true;
    case 9600: speed = B9600; return true;
    case 19200: speed = B19200; return true;
    case 38400: speed = B38400; return true;
    case 57600: speed = B57600; return true;
    case 115200: speed = B115200; return true;
    case 230400: speed = B230400; return true;
    case 460800: speed = B460800; return true;
    case 921600: speed = B921600; return true;
    default: return false;
  }
}

ModbusRtuServer::~ModbusRtuServer() { stop(); }

bool ModbusRtuServer::start(const SerialSettings& s, std::string& error) {
  unsigned speed = 0;
  if (!baud_constant(s.baud, speed)) {
    error = std::to_string(s.baud) + " is not a supported baud rate";
    return false;
  }
  fd_ = ::open(s.device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) {
    error = "cannot open '" + s.device + "': " + std::strerror(errno);
    return false;
  }
  termios t{};
  if (::tcgetattr(fd_, &t) != 0) {
    error = "'" + s.device + "' is not a serial port: " + std::strerror(errno);
    ::close(fd_);
    fd_ = -1;
    return false;
  }
  ::cfmakeraw(&t);
  ::cfsetispeed(&t, speed);
  ::cfsetospeed(&t, speed);
  t.c_cflag |= CLOCAL | CREAD;
  t.c_cflag &= ~static_cast<tcflag_t>(CSIZE | PARENB | PARODD | CSTOPB);
  t.c_cflag |= s.data_bits == 5 ? CS5 : s.data_bits == 6 ? CS6 : s.data_bits == 7 ? CS7 : CS8;
  if (s.parity == 'E') t.c_cflag |= PARENB;
  if (s.parity == 'O') t.c_cflag |= PARENB | PARODD;
  if (s.stop_bits == 2) t.c_cflag |= CSTOPB;
  ::tcsetattr(fd_, TCSANOW, &t);
  ::tcflush(fd_, TCIOFLUSH);
  // 3.5 character times end a frame; the standard fixes 1.75 ms above 19200 baud. A pty
  // delivers in bursts, so allow a few milliseconds more.
  const double char_s = 11.0 / s.baud;
  silence_s_ = std::max(0.005, 3.5 * char_s);
  stop_ = false;
  thread_ = std::thread([this] { loop(); });
  return true;
}

void ModbusRtuServer::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

RtuServerStats ModbusRtuServer::stats() const { return {frames_, crc_errors_, discarded_}; }

void ModbusRtuServer::answer(std::uint8_t* frame, std::size_t length) {
  const std::uint8_t unit = frame[0];
  if (faults_.link_cut()) {
    faults_.count_ignored_during_cut();
    return;
  }
  if (unit != 0 && !service_.serves(unit)) return;
  std::uint8_t reply[3 + modbus::kMaxPdu];
  const std::span<const std::uint8_t> pdu(frame + 1, length - 3);
  const std::span<std::uint8_t> out(reply + 1, modbus::kMaxPdu);
  const FaultAction action = unit == 0 ? FaultAction::none : faults_.decide();
  const std::size_t n = action == FaultAction::exception
                            ? modbus::exception_reply(pdu[0], modbus::kServerDeviceFailure, out)
                            : service_.handle(unit, pdu, out);
  if (n == 0 || action == FaultAction::drop) return;
  if (action == FaultAction::delay) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(faults_.plan().delay_s);
    while (!stop_ && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  reply[0] = unit;
  const std::uint16_t crc = modbus::crc16(std::span<const std::uint8_t>(reply, n + 1));
  reply[n + 1] = static_cast<std::uint8_t>(crc & 0xFF);
  reply[n + 2] = static_cast<std::uint8_t>(crc >> 8);
  if (action == FaultAction::corrupt) reply[n / 2 + 1] ^= 0x10;  // a flipped bit: the CRC no longer holds
  const std::uint8_t* p = reply;
  std::size_t left = n + 3;
  while (left > 0 && !stop_) {
    const ssize_t k = ::write(fd_, p, left);
    if (k < 0 && (errno == EAGAIN || errno == EINTR)) {
      pollfd q{fd_, POLLOUT, 0};
      ::poll(&q, 1, 10);
      continue;
    }
    if (k <= 0) return;
    p += k;
    left -= static_cast<std::size_t>(k);
  }
}

void ModbusRtuServer::loop() {
  using clock = std::chrono::steady_clock;
  std::vector<std::uint8_t> buf;
  auto last_byte = clock::now();
  bool resync = false;  // after garbage: discard until the line is silent
  while (!stop_) {
    pollfd p{fd_, POLLIN, 0};
    const int rc = ::poll(&p, 1, 2);
    if (rc > 0 && (p.revents & POLLIN)) {
      std::uint8_t chunk[512];
      const ssize_t k = ::read(fd_, chunk, sizeof chunk);
      if (k > 0) {
        buf.insert(buf.end(), chunk, chunk + k);
        last_byte = clock::now();
      }
    } else if (rc > 0 && (p.revents & (POLLHUP | POLLERR))) {
      // The other end of a pty is closed: wait for it to be opened again.
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    const bool silent = std::chrono::duration<double>(clock::now() - last_byte).count() > silence_s_;
    if (resync) {
      if (!silent) continue;
      discarded_ += buf.size();
      buf.clear();
      resync = false;
    }
    while (!buf.empty()) {
      const int need = modbus::rtu_request_length(buf);
      if (need < 0 || need > static_cast<int>(3 + modbus::kMaxPdu)) {
        resync = true;  // a function we do not know: its length is unknown
        break;
      }
      if (need == 0 || buf.size() < static_cast<std::size_t>(need)) {
        if (silent) {  // a partial frame and then silence: noise
          discarded_ += buf.size();
          buf.clear();
        }
        break;
      }
      const auto n = static_cast<std::size_t>(need);
      const std::uint16_t crc = modbus::crc16(std::span<const std::uint8_t>(buf.data(), n - 2));
      if (buf[n - 2] != (crc & 0xFF) || buf[n - 1] != (crc >> 8)) {
        ++crc_errors_;
        resync = true;
        break;
      }
      ++frames_;
      answer(buf.data(), n);
      buf.erase(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
    }
  }
}

}  // namespace synbench::emulator
