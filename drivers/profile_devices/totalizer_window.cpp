// Totalizer windows: latched counter reads and wrap-around differences.
#include "drivers/profile_devices/totalizer_window.hpp"

#include <cmath>
#include <limits>

#include "drivers/error.hpp"

namespace synbench::drivers {

std::uint64_t counter_difference(std::uint64_t start, std::uint64_t end, std::uint64_t range) {
  return end >= start ? end - start : range - start + end;
}

std::uint64_t counter_range(const ProfileSignal& s) {
  return s.encoding.type == ValueType::u16 ? (std::uint64_t{1} << 16) : (std::uint64_t{1} << 32);
}

TotalizerWindow::TotalizerWindow(SignalIo& io)
    : io_(io), plan_(io.profile(), {"total_m", "total_g", "time_base_ticks"}) {
  int i = 0;
  for (const char* n : {"total_m", "total_g", "time_base_ticks"}) {
    const ProfileSignal* s = io.profile().find(n);
    range_[i++] = s ? counter_range(*s) : 0;
  }
}

std::error_code TotalizerWindow::latch(std::uint64_t (&counts)[3]) {
  double v[3];
  if (auto ec = io_.read(plan_, v)) return ec;
  for (int i = 0; i < 3; ++i) {
    // The profile check keeps counters unscaled and unsigned; a value outside is no count.
    if (!(v[i] >= 0) || v[i] >= static_cast<double>(range_[i])) return make_error_code(errc::protocol);
    counts[i] = static_cast<std::uint64_t>(v[i]);
  }
  return {};
}

std::error_code TotalizerWindow::open(double now_s, double window_s) {
  if (auto ec = latch(start_)) return ec;
  state_ = State::open;
  close_s_ = now_s + window_s;
  return {};
}

std::error_code TotalizerWindow::poll(double now_s, bool& done) {
  done = state_ != State::open;
  if (done || now_s < close_s_ - 1e-6) return {};
  if (auto ec = latch(end_)) return ec;  // read again at the next poll
  wraps_ = 0;
  for (int i = 0; i < 3; ++i) wraps_ += end_[i] < start_[i] ? 1 : 0;
  state_ = State::done;
  done = true;
  return {};
}

void TotalizerWindow::expire() {
  if (state_ == State::open) state_ = State::expired;
}

double TotalizerWindow::next_due_s() const {
  return state_ == State::open ? close_s_ : std::numeric_limits<double>::infinity();
}

std::error_code TotalizerWindow::read(MeterReading& out) const {
  switch (state_) {
    case State::never:
    case State::open: return make_error_code(errc::not_ready);
    case State::expired: return make_error_code(errc::timeout);
    case State::done: break;
  }
  const DeviceProfile& p = io_.profile();
  const std::uint64_t ticks = counter_difference(start_[2], end_[2], range_[2]);
  if (ticks == 0 || !(p.time_base_Hz > 0)) return make_error_code(errc::invalid_argument);
  MeterReading m;
  m.counts_m = counter_difference(start_[0], end_[0], range_[0]);
  m.counts_g = counter_difference(start_[1], end_[1], range_[1]);
  m.gate_s = static_cast<double>(ticks) / p.time_base_Hz;
  m.f0_Hz = p.f0_Hz;
  m.kf_Hz_per_A = p.kf_Hz_per_A;
  m.idcm_A = (static_cast<double>(m.counts_m) / m.gate_s - p.f0_Hz) / p.kf_Hz_per_A;
  m.idcg_A = (static_cast<double>(m.counts_g) / m.gate_s - p.f0_Hz) / p.kf_Hz_per_A;
  out = m;
  return {};
}

}  // namespace synbench::drivers
