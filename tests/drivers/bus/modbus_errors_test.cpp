// Tests of the one mapping from libmodbus's errno values to synbench error codes.
#include <gtest/gtest.h>
#include <modbus.h>

#include <cerrno>

#include "drivers/bus/modbus_errors.hpp"
#include "drivers/error.hpp"

namespace synbench::drivers {
namespace {

TEST(ModbusErrors, TimeoutIsTimeout) {
  const MappedError m = map_modbus_errno(ETIMEDOUT);
  EXPECT_EQ(m.code, errc::timeout);
  EXPECT_EQ(m.fault, LinkFault::timeout);
}

TEST(ModbusErrors, EveryExceptionIsAnExceptionReplyWithItsCode) {
  for (int code = MODBUS_EXCEPTION_ILLEGAL_FUNCTION; code < MODBUS_EXCEPTION_MAX; ++code) {
    const MappedError m = map_modbus_errno(MODBUS_ENOBASE + code);
    EXPECT_EQ(m.code, errc::exception_reply) << code;
    EXPECT_EQ(m.fault, LinkFault::exception);
    EXPECT_EQ(m.exception_code, code);
  }
}

TEST(ModbusErrors, MalformedRepliesAreProtocolErrors) {
  for (int e : {EMBBADCRC, EMBBADDATA, EMBBADEXC, EMBUNKEXC, EMBMDATA, EMBBADSLAVE}) {
    const MappedError m = map_modbus_errno(e);
    EXPECT_EQ(m.code, errc::protocol) << modbus_error_text(e);
    EXPECT_EQ(m.fault, LinkFault::protocol);
  }
}

TEST(ModbusErrors, SystemErrorsAreLinkFailures) {
  for (int e : {ECONNRESET, ECONNREFUSED, EPIPE, EBADF, EIO, ENOTCONN, EHOSTUNREACH}) {
    const MappedError m = map_modbus_errno(e);
    EXPECT_EQ(m.code, errc::disconnected) << modbus_error_text(e);
    EXPECT_EQ(m.fault, LinkFault::link);
  }
  EXPECT_EQ(map_modbus_errno(EINVAL).code, errc::invalid_argument);
}

TEST(ModbusErrors, MessagesComeFromLibmodbus) {
  EXPECT_EQ(modbus_error_text(EMBBADCRC), "Invalid CRC");
  EXPECT_FALSE(modbus_error_text(ETIMEDOUT).empty());
}

}  // namespace
}  // namespace synbench::drivers
