// The bench's side of a device watchdog, as the profile's "watchdog" says: a counter (a new
// value of the heartbeat signal every period_ms), any_write (the refresh signal's last written
// value rewritten every period_ms, once the bench has written it), or none. Logic on a time
// argument; the bench's clock calls tick() while it waits (ProfileBench), so the refresh stops
// when the bench stops, which is the point of a watchdog.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <system_error>

#include "drivers/profile_devices/signal_io.hpp"

namespace synbench::drivers {

class Heartbeat {
 public:
  explicit Heartbeat(const DeviceProfile& profile) {
    const WatchdogSpec& w = profile.watchdog;
    if (w.kind == WatchdogKind::none || w.period_ms == 0) return;
    kind_ = w.kind;
    period_s_ = w.period_ms / 1000.0;
    for (const ProfileSignal& s : profile.signals)
      if (w.kind == WatchdogKind::counter ? s.role == SignalRole::heartbeat : s.name == w.refresh) signal_ = &s;
    if (!signal_) return;
    const auto& e = signal_->encoding;
    lo_ = std::isfinite(e.min) ? std::ceil(e.min) : 0.0;
    hi_ = std::isfinite(e.max) ? std::floor(e.max) : 65535.0;
    // A counter on a masked field counts within its bits.
    if (signal_->masked()) hi_ = std::min(hi_, lo_ + field_max(signal_->mask));
    if (hi_ < lo_) hi_ = lo_;
  }

  bool present() const { return signal_ && period_s_ > 0; }
  double next_due_s() const { return present() ? next_due_s_ : std::numeric_limits<double>::infinity(); }
  std::uint64_t failures() const { return failures_; }

  // Writes the next value if one is due. A failed write is retried after a quarter period, so
  // one lost request does not cost a whole period of the device's timeout.
  std::error_code tick(double now_s, SignalIo& io) {
    if (!present() || now_s < next_due_s_) return {};
    double value = 0;
    if (kind_ == WatchdogKind::any_write) {
      // Nothing to refresh before the bench's first write: the device's timer has not started.
      const auto last = io.last_written(signal_->name);
      if (!last) {
        next_due_s_ = now_s + period_s_;
        return {};
      }
      value = *last;
    } else {
      const double span = hi_ - lo_ + 1;
      value = lo_ + std::fmod(static_cast<double>(count_ + 1), span);
    }
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
  const ProfileSignal* signal_ = nullptr;
  WatchdogKind kind_ = WatchdogKind::none;
  double period_s_ = 0, lo_ = 0, hi_ = 0;
  double next_due_s_ = -std::numeric_limits<double>::infinity();
  std::uint64_t count_ = 0, failures_ = 0;
};

}  // namespace synbench::drivers
