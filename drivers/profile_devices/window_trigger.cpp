// Window start on all devices and polling for its end.
#include "drivers/profile_devices/window_trigger.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "drivers/error.hpp"

namespace synbench::drivers {

ProfileWindowTrigger::ProfileWindowTrigger(std::vector<WindowSource*> sources, const Clock& clock,
                                           double margin_s)
    : sources_(std::move(sources)), clock_(clock), margin_s_(margin_s) {}

std::error_code ProfileWindowTrigger::open_window(double window_s) {
  if (!(window_s > 0) || !std::isfinite(window_s)) return make_error_code(errc::invalid_argument);
  if (open_) return make_error_code(errc::busy);
  const double length_ms = std::round(window_s * 1000.0);
  for (WindowSource* s : sources_)
    if (auto ec = s->arm()) return ec;
  for (WindowSource* s : sources_)
    if (auto ec = s->set_length_ms(length_ms)) return ec;
  // Nothing else between the starts: each costs one transaction. Sources open in the given
  // order (ProfileBench: the drives, then the meter, whose totalizer latches after the starts).
  for (WindowSource* s : sources_)
    if (auto ec = s->open(clock_.now_s(), window_s)) return ec;
  open_ = true;
  deadline_s_ = clock_.now_s() + window_s + margin_s_;
  return {};
}

void ProfileWindowTrigger::tick(double now_s) {
  if (!open_) return;
  for (WindowSource* s : sources_) {
    if (s->next_due_s() > now_s) continue;
    bool done = false;
    if (s->poll(now_s, done)) ++poll_errors_;
  }
}

double ProfileWindowTrigger::next_due_s() const {
  double t = std::numeric_limits<double>::infinity();
  if (open_)
    for (const WindowSource* s : sources_) t = std::min(t, s->next_due_s());
  return t;
}

bool ProfileWindowTrigger::window_closed() {
  if (!open_) return true;
  const double now = clock_.now_s();
  bool all = true;
  for (WindowSource* s : sources_) {
    bool done = false;
    if (auto ec = s->poll(now, done)) {
      ++poll_errors_;
      all = false;
      continue;
    }
    all = all && done;
  }
  if (!all && now > deadline_s_) {
    for (WindowSource* s : sources_) s->expire();
    all = true;
  }
  if (all) open_ = false;
  return all;
}

}  // namespace synbench::drivers
