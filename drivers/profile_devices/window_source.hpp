// Where one device's measurement window comes from, as the trigger (ProfileWindowTrigger) drives
// it: the device itself (WindowChannel: window registers with status and sequence), the bench
// (HostWindow: telemetry polled every poll_period_ms from open to close and averaged), or a
// meter's free-running counters read at open and close (TotalizerWindow). Logic on a time
// argument: a source never sleeps, the bench's clock polls it when next_due_s() comes.
#pragma once

#include <limits>
#include <system_error>

#include "drivers/devices.hpp"

namespace synbench::drivers {

class WindowSource {
 public:
  virtual ~WindowSource() = default;
  // Who times and accumulates the window, as the point record says (`window_source`).
  virtual WindowKeeper keeper() const = 0;
  // Before any device's window opens: errc::busy while one is open.
  virtual std::error_code arm() = 0;
  // The next window's length, for a device that times its own window.
  virtual std::error_code set_length_ms(double length_ms) = 0;
  // Opens the window at `now_s` (a device's start write, a latched counter read, a first sample).
  virtual std::error_code open(double now_s, double window_s) = 0;
  // Whatever is due at `now_s`; `done` once the window opened last has closed.
  virtual std::error_code poll(double now_s, bool& done) = 0;
  // The window did not close in time: its results read as errc::timeout.
  virtual void expire() = 0;
  // When poll() has work due without being asked (a host sample); infinity: none.
  virtual double next_due_s() const { return std::numeric_limits<double>::infinity(); }
};

}  // namespace synbench::drivers
