// Window start on all devices and polling for its end.
#include "drivers/profile_devices/window_trigger.hpp"

#include <cmath>

#include "drivers/error.hpp"

namespace synbench::drivers {

ProfileWindowTrigger::ProfileWindowTrigger(std::vector<WindowChannel*> channels, const Clock& clock,
                                           double margin_s)
    : channels_(std::move(channels)), clock_(clock), margin_s_(margin_s) {}

std::error_code ProfileWindowTrigger::open_window(double window_s) {
  if (!(window_s > 0) || !std::isfinite(window_s)) return make_error_code(errc::invalid_argument);
  if (open_) return make_error_code(errc::busy);
  const double length_ms = std::round(window_s * 1000.0);
  for (WindowChannel* c : channels_)
    if (auto ec = c->arm()) return ec;
  for (WindowChannel* c : channels_)
    if (c->startable())
      if (auto ec = c->write_length_ms(length_ms)) return ec;
  // Nothing else between the starts: each costs one transaction.
  for (WindowChannel* c : channels_)
    if (c->startable())
      if (auto ec = c->start()) return ec;
  open_ = true;
  deadline_s_ = clock_.now_s() + window_s + margin_s_;
  return {};
}

bool ProfileWindowTrigger::window_closed() {
  if (!open_) return true;
  bool all = true;
  for (WindowChannel* c : channels_) {
    bool done = false;
    if (auto ec = c->poll(done)) {
      ++poll_errors_;
      all = false;
      continue;
    }
    all = all && done;
  }
  if (!all && clock_.now_s() > deadline_s_) {
    for (WindowChannel* c : channels_) c->expire();
    all = true;
  }
  if (all) open_ = false;
  return all;
}

}  // namespace synbench::drivers
