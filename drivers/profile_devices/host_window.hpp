// A window the bench keeps for a device that has none: its telemetry (a ReadPlan) is sampled
// at open, then every period on a fixed grid, and once more at the close, and each signal's
// mean, minimum, maximum and first non-zero value are kept. What such a window can see is
// limited by what the device reports and how often it is asked (docs/device-profile.md, "Host
// windows"): a sample late on the link is taken late, a grid point missed is skipped, never
// made up.
#pragma once

#include <cstdint>
#include <limits>
#include <system_error>
#include <vector>

#include "drivers/profile_devices/signal_io.hpp"
#include "drivers/profile_devices/window_source.hpp"

namespace synbench::drivers {

// The batches a host window splits its polls into by time (the drives' firmware keeps
// firmware.window_batches; the bench's own count here), and the polls it needs per batch on
// average before it keeps any: fewer leave a batch's mean to one or two polls.
inline constexpr std::size_t kHostWindowBatches = 10;
inline constexpr std::size_t kHostPollsPerBatch = 2;

class HostWindow final : public WindowSource {
 public:
  // `plan` must outlive the window; `period_s` is the profile's poll_period_ms.
  HostWindow(SignalIo& io, const ReadPlan& plan, double period_s);

  WindowKeeper keeper() const override { return WindowKeeper::host; }
  std::error_code arm() override;
  std::error_code set_length_ms(double) override { return {}; }
  std::error_code open(double now_s, double window_s) override;
  std::error_code poll(double now_s, bool& done) override;
  void expire() override;
  double next_due_s() const override;

  // Ok once the window closed with samples; errc::not_ready before, errc::timeout once
  // expired or when no sample came through.
  std::error_code result() const;
  std::uint32_t samples() const { return samples_; }
  // From the first sample to the last.
  double span_s() const { return samples_ > 0 ? last_s_ - first_s_ : 0.0; }
  // Statistics of the plan's i-th signal over the samples (NaN for a signal not mapped).
  double mean(std::size_t i) const { return samples_ > 0 ? stats_[i].sum / samples_ : nan(); }
  double min(std::size_t i) const { return stats_[i].min; }
  double max(std::size_t i) const { return stats_[i].max; }
  // The first sample's non-zero value (a fault code latched during the window), else 0, and
  // the device's own number behind it (ReadPlan::device_value: the raw code of an unknown fault).
  double first_nonzero(std::size_t i) const { return stats_[i].first_nonzero; }
  double first_nonzero_device(std::size_t i) const { return stats_[i].first_nonzero_device; }
  // The means of the plan's i-th signal over the window's kHostWindowBatches equal consecutive
  // spans of time, in time order (a sample at the close goes with the last); empty with fewer
  // than kHostPollsPerBatch x kHostWindowBatches samples, or when a span has none.
  std::vector<double> batch_means(std::size_t i) const;
  double period_s() const { return period_s_; }
  // The longest time between two samples (0 with fewer than two): a bench that stopped polling
  // (a frozen or starved master) leaves a gap no average over the window can see.
  double longest_gap_s() const { return longest_gap_s_; }

 private:
  enum class State { never, open, done, expired };
  struct Stats {
    double sum = 0, min = 0, max = 0, first_nonzero = 0, first_nonzero_device = nan();
  };
  static double nan() { return std::numeric_limits<double>::quiet_NaN(); }
  std::error_code sample(double now_s);

  SignalIo& io_;
  const ReadPlan& plan_;
  double period_s_;
  State state_ = State::never;
  double open_s_ = 0, end_s_ = 0, next_s_ = 0, first_s_ = 0, last_s_ = 0, longest_gap_s_ = 0;
  // Per batch: the samples taken in it and each signal's sum (batch-major).
  std::vector<std::uint32_t> batch_samples_;
  std::vector<double> batch_sums_;
  std::uint32_t samples_ = 0;
  std::vector<Stats> stats_;
  std::vector<double> values_;
};

}  // namespace synbench::drivers
