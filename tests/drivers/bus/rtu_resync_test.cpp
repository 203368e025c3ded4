// The RTU bus's recovery after a failed transaction, against a pseudo-terminal whose far end the
// test plays by hand: it decides what is on the line and when the far end reads the bus's
// requests, so a slow peer (a starved socat, a USB adapter still sending) is deterministic.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <stdlib.h>
#include <termios.h>
#include <unistd.h>

#include <cstdint>
#include <string>
#include <vector>

#include "drivers/bus/modbus_bus.hpp"
#include "drivers/error.hpp"

namespace synbench::drivers {
namespace {

std::uint16_t crc16(const std::vector<std::uint8_t>& bytes) {
  std::uint16_t crc = 0xFFFF;
  for (const std::uint8_t b : bytes) {
    crc ^= b;
    for (int i = 0; i < 8; ++i) crc = (crc & 1) ? static_cast<std::uint16_t>((crc >> 1) ^ 0xA001) : static_cast<std::uint16_t>(crc >> 1);
  }
  return crc;
}

std::vector<std::uint8_t> with_crc(std::vector<std::uint8_t> frame) {
  const std::uint16_t crc = crc16(frame);
  frame.push_back(static_cast<std::uint8_t>(crc & 0xFF));
  frame.push_back(static_cast<std::uint8_t>(crc >> 8));
  return frame;
}

// The master side of a pseudo-terminal: the bus opens the slave by its path. In packet mode
// (TIOCPKT) the master also learns of every flush the bus makes of its side: whether a request
// still in the kernel's buffers was thrown away (TIOCPKT_FLUSHWRITE) is then seen for certain,
// not only when the flush beats the kernel's delivery to this side (which a loaded machine, or
// a real UART still sending, makes likely, and an idle test machine rare).
class HandPlayedPeer {
 public:
  HandPlayedPeer() {
    fd_ = ::posix_openpt(O_RDWR | O_NOCTTY);
    if (fd_ < 0 || ::grantpt(fd_) != 0 || ::unlockpt(fd_) != 0) return;
    termios t{};
    ::tcgetattr(fd_, &t);
    ::cfmakeraw(&t);
    ::tcsetattr(fd_, TCSANOW, &t);
    int on = 1;
    if (::ioctl(fd_, TIOCPKT, &on) != 0) return;
    path_ = ::ptsname(fd_);
  }
  ~HandPlayedPeer() {
    if (fd_ >= 0) ::close(fd_);
  }
  bool ok() const { return !path_.empty(); }
  const std::string& path() const { return path_; }
  void send(const std::vector<std::uint8_t>& bytes) { ASSERT_EQ(::write(fd_, bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size())); }
  // Everything the bus has put on the line so far (waits up to `timeout_ms` for the first byte);
  // the flushes it made are collected in flushes().
  std::vector<std::uint8_t> received(int timeout_ms = 100) {
    std::vector<std::uint8_t> out;
    for (;;) {
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, out.empty() ? timeout_ms : 10) <= 0) return out;
      std::uint8_t buf[256];
      const ssize_t n = ::read(fd_, buf, sizeof buf);
      if (n <= 0) return out;
      // Packet mode: a data packet starts with TIOCPKT_DATA (0), a status packet is one byte.
      if (buf[0] == TIOCPKT_DATA) out.insert(out.end(), buf + 1, buf + n);
      else flushes_ |= buf[0];
    }
  }
  // TIOCPKT_FLUSHREAD: the bus discarded its input; TIOCPKT_FLUSHWRITE: its output.
  int flushes() const { return flushes_; }
  // Forgets what came before (the bus's flush when it opens the port).
  void forget() {
    received(20);
    flushes_ = 0;
  }

 private:
  int fd_ = -1;
  std::string path_;
  int flushes_ = 0;
};

ModbusLinkOptions fast() {
  ModbusLinkOptions o;
  o.response_timeout_s = 0.1;
  o.byte_timeout_s = 0.02;
  o.rtu_quiet_s = 0.02;
  return o;
}

// A late reply (to a request that timed out earlier) arrives right after the next request was
// written, before the far end took that request off the line. The mismatch is a protocol error
// and the bus resynchronises; the request itself must still reach the far end: discarding it
// with the late bytes (tcflush(TCIOFLUSH), libmodbus's modbus_flush on RTU) lost a drive's
// disable for as long as every retry met the same fate.
TEST(ModbusRtuBus, ResynchronisingKeepsTheRequestJustSent) {
  HandPlayedPeer peer;
  if (!peer.ok()) GTEST_SKIP() << "no pseudo-terminal";
  RtuPort port;
  port.device = peer.path();
  ModbusRtuBus bus(port, fast());
  ASSERT_FALSE(bus.connect()) << bus.last_error();
  peer.forget();
  // The reply of an earlier "read holding 16+2" of unit 1, late.
  peer.send(with_crc({0x01, 0x03, 0x04, 0x44, 0x48, 0x00, 0x00}));
  const std::uint8_t off = 0;
  const std::error_code ec = bus.write_bits(1, 0, std::span(&off, 1));
  EXPECT_EQ(ec, make_error_code(errc::protocol)) << bus.last_error();
  EXPECT_EQ(bus.stats().protocol_errors, 1u);
  // The disable (write single coil 0 of unit 1, off) is on the line, once; the bus flushed its
  // input, never its output.
  EXPECT_EQ(peer.received(), with_crc({0x01, 0x05, 0x00, 0x00, 0x00, 0x00}));
  EXPECT_TRUE(peer.flushes() & TIOCPKT_FLUSHREAD) << peer.flushes();
  EXPECT_FALSE(peer.flushes() & TIOCPKT_FLUSHWRITE) << "the request just written was thrown away";
}

// What the resynchronisation must still discard: the late bytes themselves, so the next
// transaction takes its own reply and not the stale one.
TEST(ModbusRtuBus, ResynchronisingDiscardsTheLateReply) {
  HandPlayedPeer peer;
  if (!peer.ok()) GTEST_SKIP() << "no pseudo-terminal";
  RtuPort port;
  port.device = peer.path();
  ModbusRtuBus bus(port, fast());
  ASSERT_FALSE(bus.connect()) << bus.last_error();
  peer.forget();
  peer.send(with_crc({0x01, 0x03, 0x04, 0x44, 0x48, 0x00, 0x00}));
  peer.send(with_crc({0x01, 0x03, 0x04, 0x44, 0x49, 0x00, 0x00}));  // and another, in the same burst
  const std::uint8_t off = 0;
  EXPECT_EQ(bus.write_bits(1, 0, std::span(&off, 1)), make_error_code(errc::protocol));
  EXPECT_EQ(peer.received(), with_crc({0x01, 0x05, 0x00, 0x00, 0x00, 0x00}));
  // The repeat gets its own echo.
  peer.send(with_crc({0x01, 0x05, 0x00, 0x00, 0x00, 0x00}));
  EXPECT_FALSE(bus.write_bits(1, 0, std::span(&off, 1))) << bus.last_error();
  EXPECT_EQ(peer.received(), with_crc({0x01, 0x05, 0x00, 0x00, 0x00, 0x00}));
}

}  // namespace
}  // namespace synbench::drivers
