// Which failed requests the profile devices repeat, and for how long. A real RS-485 line loses,
// garbles and delays a few replies in a hundred, and a device answers "busy" now and then; none
// of that is a dead link, and one such reply must not end a sweep. A repeat is made only when
// it cannot change what the request means (reads, idempotent writes), only for failures that
// say nothing about the request itself (no reply, a garbled reply, a transient exception), and
// only while the bench's telemetry deadline leaves room: a link that stays bad is for the
// safety supervisor's link_loss, not for an endless loop here.
#pragma once

#include <system_error>

#include "drivers/error.hpp"

namespace synbench::drivers {

struct RetryPolicy {
  // No repeat starts later than this after the first attempt, in bench time. Below the safety
  // supervisor's 0.5 s telemetry deadline and the drives' 0.5 s watchdog, less a heartbeat
  // period: a read that exhausts it, and the next tick's read, still come before either.
  double budget_s = 0.25;
  // At most this many repeats, whatever the time (on virtual time a transaction takes none).
  int max_retries = 3;
};

// Modbus exceptions that say "not now" rather than "never": 4 server device failure (what a
// drive answers while an internal task holds the bus; `synbench emulate`'s injected exception),
// 5 acknowledge, 6 server device busy, 10 and 11 a gateway that could not reach the device.
// 1 (illegal function), 2 (illegal address) and 3 (illegal value) would come back every time.
constexpr bool transient_exception(int code) {
  return code == 4 || code == 5 || code == 6 || code == 10 || code == 11;
}

// Whether a request that failed with `ec` may succeed when repeated: no reply (timeout), a
// malformed or mismatched one (the bus resynchronised, so a repeat cannot take the lost reply
// for its own), or a transient exception. A link that is down (errc::disconnected) is not
// repeated: the bus refuses at once during its reconnection backoff, and the caller's next
// tick is the retry.
inline bool retryable(std::error_code ec, int exception_code) {
  if (ec == errc::timeout || ec == errc::protocol) return true;
  return ec == errc::exception_reply && transient_exception(exception_code);
}

}  // namespace synbench::drivers
