// Window protocol of a profile device: sequence-checked results.
#include "drivers/profile_devices/window_channel.hpp"

#include <string_view>

#include "drivers/error.hpp"

namespace synbench::drivers {
namespace {

constexpr double kStatusOpen = 1, kStatusDone = 2;

const ProfileSignal* by_role(const DeviceProfile& p, SignalRole role) {
  for (const ProfileSignal& s : p.signals)
    if (s.role == role) return &s;
  return nullptr;
}

std::string_view name_or_empty(const ProfileSignal* s) { return s ? std::string_view(s->name) : std::string_view(); }

}  // namespace

WindowChannel::WindowChannel(SignalIo& io)
    : io_(io),
      status_(by_role(io.profile(), SignalRole::window_status)),
      sequence_(by_role(io.profile(), SignalRole::window_sequence)),
      length_(by_role(io.profile(), SignalRole::window_length)),
      start_(by_role(io.profile(), SignalRole::window_start)),
      status_plan_(io.profile(), {name_or_empty(status_), name_or_empty(sequence_)}) {}

std::error_code WindowChannel::read_status(double& status, double& sequence) {
  if (!status_ || !sequence_) return make_error_code(errc::not_supported);
  double v[2];
  if (auto ec = io_.read(status_plan_, v)) return ec;
  status = v[0];
  sequence = v[1];
  return {};
}

std::error_code WindowChannel::arm() {
  double status = 0, sequence = 0;
  if (auto ec = read_status(status, sequence)) return ec;
  if (status == kStatusOpen) return make_error_code(errc::busy);
  armed_sequence_ = sequence;
  state_ = State::armed;
  return {};
}

std::error_code WindowChannel::write_length_ms(double length_ms) {
  if (!length_) return make_error_code(errc::not_supported);
  return io_.write(length_->name, length_ms);
}

std::error_code WindowChannel::start() {
  if (!start_) return make_error_code(errc::not_supported);
  const double first_s = io_.now_s();
  for (int repeats = 0;; ++repeats) {
    const std::error_code ec = io_.write(start_->name, 1);  // SignalIo never repeats a start
    if (!ec) return {};
    if (!retryable(ec, io_.bus().last_exception_code()) || state_ != State::armed) return ec;
    // Executed or not? The device knows (the read is itself retried within the budget).
    double status = 0, sequence = 0;
    if (read_status(status, sequence)) return ec;
    if (status == kStatusOpen || (status == kStatusDone && sequence != armed_sequence_)) {
      ++starts_confirmed_;
      return {};
    }
    if (!io_.may_repeat(ec, repeats, first_s)) return ec;
    ++start_repeats_;
  }
}

std::error_code WindowChannel::poll(bool& done) {
  done = state_ != State::armed;
  if (done) return {};
  double status = 0, sequence = 0;
  if (auto ec = read_status(status, sequence)) return ec;
  if (status == kStatusDone && sequence != armed_sequence_) {
    state_ = State::done;
    done_sequence_ = sequence;
    done = true;
  }
  return {};
}

std::error_code WindowChannel::read_results(const ReadPlan& plan, std::span<double> values) {
  switch (state_) {
    case State::never: return make_error_code(errc::not_ready);
    case State::expired: return make_error_code(errc::timeout);
    case State::armed:
    case State::done: break;
  }
  if (plan.size() < 2 || !plan.present(0) || !plan.present(1)) return make_error_code(errc::not_supported);
  if (auto ec = io_.read(plan, values)) return ec;
  if (values[0] != kStatusDone || values[1] == armed_sequence_) return make_error_code(errc::not_ready);
  if (state_ == State::done && values[1] != done_sequence_) return make_error_code(errc::protocol);
  // The results may span several requests: confirm no other window closed meanwhile.
  double status = 0, sequence = 0;
  if (auto ec = read_status(status, sequence)) return ec;
  if (status != kStatusDone || sequence != values[1]) return make_error_code(errc::not_ready);
  state_ = State::done;
  done_sequence_ = sequence;
  return {};
}

}  // namespace synbench::drivers
