// Opens one measurement window on several devices' window sources at once: the length goes to
// each first, then the start coils are written back to back, so the windows open as close
// together as the link allows (on the twin they share one trigger and open in the same control
// period), in the order given; a totalizer's latched read and a host window's first sample are
// no start write and cost the others nothing. The window
// counts as closed when every source is done (a device reports done with a new sequence
// number, a host window has sampled to its end), or when its deadline passes (then the
// results read as errc::timeout, never as old data). tick() does the host sampling due in
// between, so it keeps its grid whenever the bench's clock runs.
#pragma once

#include <system_error>
#include <vector>

#include "drivers/clock.hpp"
#include "drivers/devices.hpp"
#include "drivers/profile_devices/window_source.hpp"

namespace synbench::drivers {

class ProfileWindowTrigger final : public WindowTrigger {
 public:
  // `margin_s`: how long after the window's nominal end the bench waits for all devices.
  ProfileWindowTrigger(std::vector<WindowSource*> sources, const Clock& clock, double margin_s = 5.0);

  std::error_code open_window(double window_s) override;
  bool window_closed() override;
  // The work the sources have due at `now_s` (host samples); errors count as poll errors.
  void tick(double now_s);
  // When a source next has work due (infinity: none, or no window open).
  double next_due_s() const;
  // Transient errors while polling for the end of a window (they are retried on the next poll).
  std::uint64_t poll_errors() const { return poll_errors_; }

 private:
  std::vector<WindowSource*> sources_;
  const Clock& clock_;
  double margin_s_;
  bool open_ = false;
  double deadline_s_ = 0;
  std::uint64_t poll_errors_ = 0;
};

}  // namespace synbench::drivers
