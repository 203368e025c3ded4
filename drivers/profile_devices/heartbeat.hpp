// The bench's side of a device watchdog: a new value of the heartbeat signal every period_ms.
// Logic on a time argument; the bench's clock calls tick() while it waits (ProfileBench), so the
// heartbeat stops when the bench stops, which is the point of a watchdog.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <system_error>

#include "drivers/profile_devices/signal_io.hpp"

namespace synbench::drivers {

class Heartbeat {
 public:
  // `signal` is the profile's heartbeat, or null for a device without one (the meter).
  explicit Heartbeat(const ProfileSignal* signal) : signal_(signal) {
    if (!signal_ || !signal_->heartbeat) return;
    period_s_ = signal_->heartbeat->period_ms / 1000.0;
    const auto& e = signal_->encoding;
    lo_ = std::isfinite(e.min) ? std::ceil(e.min) : 0.0;
    hi_ = std::isfinite(e.max) ? std::floor(e.max) : 65535.0;
    if (hi_ < lo_) hi_ = lo_;
  }

  bool present() const { return signal_ && period_s_ > 0; }
  double next_due_s() const { return present() ? next_due_s_ : std::numeric_limits<double>::infinity(); }
  std::uint64_t failures() const { return failures_; }

  // Writes the next value if one is due. A failed write is retried after a quarter period, so
  // one lost request does not cost a whole period of the device's timeout.
  std::error_code tick(double now_s, SignalIo& io) {
    if (!present() || now_s < next_due_s_) return {};
    const double span = hi_ - lo_ + 1;
    const double value = lo_ + std::fmod(static_cast<double>(count_ + 1), span);
    if (auto ec = io.write(signal_->name, value)) {
      ++failures_;
      next_due_s_ = now_s + period_s_ / 4;
      return ec;
    }
    ++count_;
    next_due_s_ = now_s + period_s_;
    return {};
  }

 private:
  const ProfileSignal* signal_;
  double period_s_ = 0, lo_ = 0, hi_ = 0;
  double next_due_s_ = -std::numeric_limits<double>::infinity();
  std::uint64_t count_ = 0, failures_ = 0;
};

}  // namespace synbench::drivers
