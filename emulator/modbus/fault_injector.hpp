// Link faults for tests, injected by the emulator's TCP and RTU servers: a request's reply can
// be delayed past the master's timeout, dropped, replaced by an exception, or corrupted (RTU:
// a flipped bit, so the CRC fails; TCP: a wrong transaction id, since TCP itself guards the
// bytes), each with its own probability; and the whole link can be cut for a while. Every
// injected fault is counted by kind, so a test can hold the master's counts against them.
#pragma once

#include <chrono>
#include <cstdint>
#include <mutex>
#include <random>

namespace synbench::emulator {

struct FaultPlan {
  double delay_pct = 0;      // of replies, sent late by delay_s
  double drop_pct = 0;       // of requests, executed but never answered
  double exception_pct = 0;  // of requests, not executed, answered SERVER_DEVICE_FAILURE
  double corrupt_pct = 0;    // of replies, corrupted
  double delay_s = 1.0;
  std::uint32_t seed = 1;
};

enum class FaultAction { none, delay, drop, exception, corrupt };

struct FaultCounts {
  std::uint64_t requests = 0;  // answered or faulted (requests during a cut not included)
  std::uint64_t delayed = 0, dropped = 0, exceptions = 0, corrupted = 0;
  std::uint64_t ignored_during_cut = 0;
  std::uint64_t cuts = 0;
};

class FaultInjector {
 public:
  explicit FaultInjector(const FaultPlan& plan = {}) : plan_(plan), rng_(plan.seed) {}

  const FaultPlan& plan() const { return plan_; }
  // Draws the fate of one request's reply and counts it.
  FaultAction decide();

  // Cuts the link for `seconds` of wall time from now.
  void cut_link(double seconds);
  bool link_cut() const;
  void count_ignored_during_cut();

  FaultCounts counts() const;

 private:
  FaultPlan plan_;
  mutable std::mutex mutex_;
  std::mt19937 rng_;
  FaultCounts counts_;
  std::chrono::steady_clock::time_point cut_until_{};
};

}  // namespace synbench::emulator
