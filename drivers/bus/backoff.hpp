// Bounded exponential backoff for reconnecting a link: the first attempt after a failure waits
// `initial_s`, each further failure doubles the wait up to `max_s`, a success resets it. Pure
// logic on a time argument, so it is tested without waiting.
#pragma once

#include <algorithm>

namespace synbench::drivers {

class Backoff {
 public:
  Backoff(double initial_s, double max_s) : initial_s_(initial_s), max_s_(std::max(initial_s, max_s)) {}

  // Whether a connection attempt may be made at `now_s`.
  bool may_attempt(double now_s) const { return now_s >= next_attempt_s_; }
  void failed(double now_s) {
    delay_s_ = delay_s_ == 0 ? initial_s_ : std::min(2 * delay_s_, max_s_);
    next_attempt_s_ = now_s + delay_s_;
  }
  void succeeded() {
    delay_s_ = 0;
    next_attempt_s_ = 0;
  }
  // The wait after the last failure (0 before any).
  double delay_s() const { return delay_s_; }
  double next_attempt_s() const { return next_attempt_s_; }

 private:
  double initial_s_, max_s_;
  double delay_s_ = 0, next_attempt_s_ = 0;
};

}  // namespace synbench::drivers
