// The one place where libmodbus's errno values become synbench error codes. Every failed
// libmodbus call goes through map_modbus_errno(), so each error is translated once, at the
// boundary, and counted by kind.
#pragma once

#include <string>
#include <system_error>

namespace synbench::drivers {

// What a failure says about the link, which decides the recovery.
enum class LinkFault {
  timeout,    // no (complete) reply in time: a late reply may still be on its way
  exception,  // a well-formed exception reply: the link is fine
  protocol,   // bad CRC, mismatched transaction, unit or function, malformed reply
  link,       // the connection or port failed: close and reconnect
  invalid,    // the request itself was refused before it reached the wire
};

struct MappedError {
  std::error_code code;    // in synbench's category
  LinkFault fault = LinkFault::link;
  int exception_code = 0;  // Modbus exception code (1..11) for LinkFault::exception
};

// `err` is errno after a libmodbus call returned -1.
MappedError map_modbus_errno(int err);

// libmodbus's message for `err` (modbus_strerror, which also covers the system's errno values).
std::string modbus_error_text(int err);

}  // namespace synbench::drivers
