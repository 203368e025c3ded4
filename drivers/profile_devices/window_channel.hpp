// One device's measurement window over Modbus (the window_* or gate_* signals): arm, start,
// poll, read. Results are accepted only when the status is done and the sequence number has
// moved on since this bench started the window, and the sequence is read again after the
// results: results of an earlier window never pass for the current one.
#pragma once

#include <cstdint>
#include <span>
#include <system_error>

#include "drivers/profile_devices/signal_io.hpp"
#include "drivers/profile_devices/window_source.hpp"

namespace synbench::drivers {

class WindowChannel final : public WindowSource {
 public:
  // The profile's signals of roles window_status, window_sequence, window_length, window_start.
  explicit WindowChannel(SignalIo& io);

  // Whether the bench can start the window itself (the load drive may lack a start coil and be
  // wired to a trigger line instead).
  bool startable() const { return length_ && start_; }
  const ProfileSignal* status_signal() const { return status_; }
  const ProfileSignal* sequence_signal() const { return sequence_; }

  // Reads the sequence the next window must move on from; errc::busy while one is open.
  std::error_code arm() override;
  std::error_code write_length_ms(double length_ms);
  // Writes the start once. When the write fails in a way that leaves open whether the device
  // executed it (no reply, a garbled reply, a transient exception), the device is asked: a
  // window open, or closed with a sequence past the armed one, means the start was executed;
  // status and sequence unchanged mean it was not, and only then is it written again (within
  // the retry policy). A blind repeat could start a second window, or be refused as busy.
  std::error_code start();
  // Starts written again after a lost reply, and starts found executed by the read-back.
  std::uint64_t start_repeats() const { return start_repeats_; }
  std::uint64_t starts_confirmed() const { return starts_confirmed_; }
  // Reads status and sequence (no I/O once done); `done` when the armed window has closed.
  std::error_code poll(bool& done);
  // The window did not close in time: its results are reported as errc::timeout.
  void expire() override {
    if (state_ == State::armed) state_ = State::expired;
  }

  // As a WindowSource: a device without start and length (a trigger line opens its window)
  // only arms and polls.
  WindowKeeper keeper() const override { return WindowKeeper::device; }
  std::error_code set_length_ms(double length_ms) override {
    return startable() ? write_length_ms(length_ms) : std::error_code{};
  }
  std::error_code open(double, double) override { return startable() ? start() : std::error_code{}; }
  std::error_code poll(double, bool& done) override { return poll(done); }

  // Reads `plan`, whose first two signals must be the status and the sequence, and checks it
  // is the armed window's result. errc::not_ready before it closed or when no window was
  // started by this bench, errc::timeout once expired.
  std::error_code read_results(const ReadPlan& plan, std::span<double> values);

 private:
  enum class State { never, armed, done, expired };
  std::error_code read_status(double& status, double& sequence);

  SignalIo& io_;
  const ProfileSignal *status_ = nullptr, *sequence_ = nullptr, *length_ = nullptr, *start_ = nullptr;
  ReadPlan status_plan_;
  State state_ = State::never;
  double armed_sequence_ = 0, done_sequence_ = 0;
  std::uint64_t start_repeats_ = 0, starts_confirmed_ = 0;
};

}  // namespace synbench::drivers
