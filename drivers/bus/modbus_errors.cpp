// libmodbus errno -> errc, with the link fault that decides the recovery.
#include "drivers/bus/modbus_errors.hpp"

#include <modbus.h>

#include <cerrno>

#include "drivers/error.hpp"

namespace synbench::drivers {

MappedError map_modbus_errno(int err) {
  if (err > MODBUS_ENOBASE && err < MODBUS_ENOBASE + MODBUS_EXCEPTION_MAX)
    return {make_error_code(errc::exception_reply), LinkFault::exception, err - MODBUS_ENOBASE};
  switch (err) {
    case ETIMEDOUT:
      return {make_error_code(errc::timeout), LinkFault::timeout, 0};
    case EMBBADCRC:    // RTU frame with a wrong checksum
    case EMBBADDATA:   // transaction id, function or byte count not those of the request
    case EMBBADEXC:    // exception reply of the wrong length
    case EMBUNKEXC:    // exception code outside the standard ones
    case EMBMDATA:     // more data than a frame can hold
    case EMBBADSLAVE:  // reply from another unit id
      return {make_error_code(errc::protocol), LinkFault::protocol, 0};
    case EINVAL:
    case ENOMEM:
      return {make_error_code(errc::invalid_argument), LinkFault::invalid, 0};
    default:
      // ECONNRESET, ECONNREFUSED, EPIPE, EBADF, ENOTCONN, EIO, ENXIO, EHOSTUNREACH, ...: the link
      // is gone whatever the exact cause, and the recovery is the same.
      return {make_error_code(errc::disconnected), LinkFault::link, 0};
  }
}

std::string modbus_error_text(int err) { return modbus_strerror(err); }

}  // namespace synbench::drivers
