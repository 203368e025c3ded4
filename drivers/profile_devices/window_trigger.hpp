// Opens one measurement window on several profile devices at once: the length goes to each
// first, then the start coils are written back to back, so the windows open as close together
// as the link allows (on the twin they share one trigger and open in the same control period).
// The window counts as closed when every device reports done with a new sequence number, or
// when its deadline passes (then the results read as errc::timeout, never as old data).
#pragma once

#include <system_error>
#include <vector>

#include "drivers/clock.hpp"
#include "drivers/devices.hpp"
#include "drivers/profile_devices/window_channel.hpp"

namespace synbench::drivers {

class ProfileWindowTrigger final : public WindowTrigger {
 public:
  // `margin_s`: how long after the window's nominal end the bench waits for all devices.
  ProfileWindowTrigger(std::vector<WindowChannel*> channels, const Clock& clock, double margin_s = 5.0);

  std::error_code open_window(double window_s) override;
  bool window_closed() override;
  // Transient errors while polling for the end of a window (they are retried on the next poll).
  std::uint64_t poll_errors() const { return poll_errors_; }

 private:
  std::vector<WindowChannel*> channels_;
  const Clock& clock_;
  double margin_s_;
  bool open_ = false;
  double deadline_s_ = 0;
  std::uint64_t poll_errors_ = 0;
};

}  // namespace synbench::drivers
