// Host-kept windows: sampling on a grid driven by the bench's clock.
#include "drivers/profile_devices/host_window.hpp"

#include <algorithm>
#include <cmath>

#include "drivers/error.hpp"

namespace synbench::drivers {
namespace {

// A virtual clock stops within a microsecond of the time it was asked for.
constexpr double kDueSlack_s = 1e-6;

}  // namespace

HostWindow::HostWindow(SignalIo& io, const ReadPlan& plan, double period_s)
    : io_(io), plan_(plan), period_s_(period_s), stats_(plan.size()), values_(plan.size()) {}

std::error_code HostWindow::arm() {
  return state_ == State::open ? make_error_code(errc::busy) : std::error_code{};
}

std::error_code HostWindow::open(double now_s, double window_s) {
  if (state_ == State::open) return make_error_code(errc::busy);
  state_ = State::open;
  open_s_ = now_s;
  end_s_ = now_s + window_s;
  batch_samples_.assign(kHostWindowBatches, 0);
  batch_sums_.assign(kHostWindowBatches * stats_.size(), 0.0);
  next_s_ = now_s;
  samples_ = 0;
  longest_gap_s_ = 0;
  std::fill(stats_.begin(), stats_.end(), Stats{});
  return {};
}

std::error_code HostWindow::sample(double now_s) {
  if (auto ec = io_.read(plan_, values_)) return ec;  // retried at the next poll: next_s_ stays
  for (std::size_t i = 0; i < stats_.size(); ++i) {
    Stats& s = stats_[i];
    const double v = values_[i];
    s.sum += v;
    s.min = samples_ == 0 ? v : std::min(s.min, v);
    s.max = samples_ == 0 ? v : std::max(s.max, v);
    if (s.first_nonzero == 0 && v != 0 && v == v) {
      s.first_nonzero = v;
      s.first_nonzero_device = plan_.device_value(i);
    }
  }
  // The batch of the sample's time: equal spans of the window from its open to its close.
  const double span_s = (end_s_ - open_s_) / static_cast<double>(kHostWindowBatches);
  const double b = span_s > 0 ? std::floor((now_s - open_s_ + kDueSlack_s) / span_s) : 0.0;
  const auto batch = static_cast<std::size_t>(std::clamp(b, 0.0, static_cast<double>(kHostWindowBatches - 1)));
  ++batch_samples_[batch];
  for (std::size_t i = 0; i < stats_.size(); ++i) batch_sums_[batch * stats_.size() + i] += values_[i];
  if (samples_ == 0) first_s_ = now_s;
  if (samples_ > 0) longest_gap_s_ = std::max(longest_gap_s_, now_s - last_s_);
  last_s_ = now_s;
  ++samples_;
  // The next point of the grid after now: a late sample does not shift the grid, a missed
  // point is skipped.
  while (next_s_ <= now_s + kDueSlack_s) next_s_ += period_s_;
  return {};
}

std::error_code HostWindow::poll(double now_s, bool& done) {
  done = state_ != State::open;
  if (done) return {};
  const bool closing = now_s >= end_s_ - kDueSlack_s;
  // At the close, one last sample if a grid point fell since the previous one.
  if (now_s >= next_s_ - kDueSlack_s || (closing && next_s_ <= end_s_ + kDueSlack_s))
    if (auto ec = sample(now_s)) return ec;
  if (closing) {
    state_ = State::done;
    done = true;
  }
  return {};
}

void HostWindow::expire() {
  if (state_ == State::open) state_ = State::expired;
}

double HostWindow::next_due_s() const {
  return state_ == State::open ? std::min(next_s_, end_s_) : std::numeric_limits<double>::infinity();
}

std::vector<double> HostWindow::batch_means(std::size_t i) const {
  std::vector<double> means;
  if (samples_ < kHostPollsPerBatch * kHostWindowBatches || i >= stats_.size()) return means;
  for (std::size_t k = 0; k < kHostWindowBatches; ++k) {
    if (batch_samples_[k] == 0) return {};
    means.push_back(batch_sums_[k * stats_.size() + i] / batch_samples_[k]);
  }
  return means;
}

std::error_code HostWindow::result() const {
  switch (state_) {
    case State::never:
    case State::open: return make_error_code(errc::not_ready);
    case State::expired: return make_error_code(errc::timeout);
    case State::done: break;
  }
  // Every sample lost on the link: nothing was measured.
  return samples_ > 0 ? std::error_code{} : make_error_code(errc::timeout);
}

}  // namespace synbench::drivers
