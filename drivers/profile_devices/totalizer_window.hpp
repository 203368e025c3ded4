// A meter's window from free-running counters (meter "totalizer"): the two VFC pulse counters
// and the time-base counter are read together (one request where the profile puts them next to
// each other, so the device latches them at one instant) when the window opens and again once
// it has lasted its length. The differences are taken modulo each counter's range, so a
// counter that wrapped during the window counts on, and the gate is d(ticks) / time_base_Hz:
// the meter's own clock times the window, not the bench's.
#pragma once

#include <cstdint>
#include <system_error>

#include "drivers/devices.hpp"
#include "drivers/profile_devices/signal_io.hpp"
#include "drivers/profile_devices/window_source.hpp"

namespace synbench::drivers {

// (end - start) modulo `range`: the counts of a counter that wraps at `range` (one wrap at most
// per window, which the window's length must guarantee).
std::uint64_t counter_difference(std::uint64_t start, std::uint64_t end, std::uint64_t range);
// The range of a counter signal of type u16 or u32 (2^16, 2^32).
std::uint64_t counter_range(const ProfileSignal& s);

class TotalizerWindow final : public WindowSource {
 public:
  // The profile (kind vfc_meter, meter totalizer) of `io`.
  explicit TotalizerWindow(SignalIo& io);

  WindowKeeper keeper() const override { return WindowKeeper::device; }
  std::error_code arm() override { return {}; }
  std::error_code set_length_ms(double) override { return {}; }
  std::error_code open(double now_s, double window_s) override;
  std::error_code poll(double now_s, bool& done) override;
  void expire() override;
  double next_due_s() const override;

  // The window's counts, gate and currents (f0_Hz, kf_Hz_per_A of the profile); errc::not_ready
  // before it closed, errc::timeout once expired, errc::invalid_argument for a time base that
  // did not advance.
  std::error_code read(MeterReading& out) const;
  // How many of the three counters wrapped during the last window (for logs and tests).
  int wraps() const { return wraps_; }
  // The counters (total_m, total_g, time_base_ticks) as latched at the last open.
  const std::uint64_t (&open_counts() const)[3] { return start_; }

 private:
  enum class State { never, open, done, expired };
  std::error_code latch(std::uint64_t (&counts)[3]);

  SignalIo& io_;
  ReadPlan plan_;
  std::uint64_t range_[3] = {0, 0, 0};
  std::uint64_t start_[3] = {0, 0, 0}, end_[3] = {0, 0, 0};
  State state_ = State::never;
  double close_s_ = 0;
  int wraps_ = 0;
};

}  // namespace synbench::drivers
