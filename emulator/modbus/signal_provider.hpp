// What stands behind a register map: the values of a device's signals by name, and what a
// write does. RegisterServer does the Modbus side (tables, encoding, limits, exceptions) from
// the profiles; a provider only deals in engineering values, so the twin's firmware never sees
// a register.
#pragma once

#include <cstddef>
#include <limits>
#include <system_error>

#include "drivers/profile/device_profile.hpp"

namespace synbench::emulator {

class SignalProvider {
 public:
  virtual ~SignalProvider() = default;
  // Engineering value of a signal of `device` (enumerated signals as the bench's code, bits as
  // 0 or 1). Also called for command signals: their last accepted value.
  virtual double read_signal(drivers::DeviceKind device, const drivers::ProfileSignal& s) = 0;
  // Value `k` of an array signal (a profile's "count"); NaN (served as 0) when there is none,
  // as for a window without batches.
  virtual double read_element(drivers::DeviceKind /*device*/, const drivers::ProfileSignal& /*s*/,
                              std::size_t /*k*/) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  // Applies a write of an engineering value already checked against the signal's limits.
  // errc::invalid_argument or not_supported (answered ILLEGAL_DATA_VALUE), errc::busy
  // (SERVER_DEVICE_BUSY), anything else (SERVER_DEVICE_FAILURE).
  virtual std::error_code write_signal(drivers::DeviceKind device, const drivers::ProfileSignal& s, double value) = 0;
  // A write request to one of `device`'s registers was accepted, whether or not it changed a
  // signal (a rewritten control word): what an any-write watchdog counts.
  virtual void accepted_write(drivers::DeviceKind /*device*/) {}
};

}  // namespace synbench::emulator
