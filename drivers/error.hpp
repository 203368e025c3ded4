// synbench's own error category: every device or transport failure is translated once, at the
// boundary where it happens, into one of these codes.
#pragma once

#include <system_error>

namespace synbench {

enum class errc {
  ok = 0,
  timeout = 1,          // no reply within the response timeout
  disconnected,         // link down; reconnect pending
  protocol,             // malformed or mismatched reply
  exception_reply,      // device answered with a Modbus exception
  invalid_argument,     // value outside the signal's limits or type
  not_supported,        // the device (or its profile) has no such signal
  device_fault,         // the device reports a latched fault
  busy,                 // a window or command is already in progress
  not_ready,            // result not yet available
};

const std::error_category& error_category() noexcept;

inline std::error_code make_error_code(errc e) noexcept {
  return {static_cast<int>(e), error_category()};
}

}  // namespace synbench

template <>
struct std::is_error_code_enum<synbench::errc> : std::true_type {};
