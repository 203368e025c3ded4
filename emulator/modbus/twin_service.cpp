// Serialized access to the twin and its real-time (or scaled-time) thread.
#include "emulator/modbus/twin_service.hpp"

#include <chrono>
#include <cmath>

namespace synbench::emulator {
namespace {

// Twin periods per wake-up of the real-time thread (1 ms); TwinSignals checks the watchdog and
// the window every 10 periods regardless.
constexpr std::int64_t kChunkSteps = 10;
// Most periods run under one hold of the lock while catching up (10 ms of twin time, some 4 us
// of CPU each): a request waits at most that long, and the twin never gives its CPU away
// between chunks (a yield there can cost a whole timeslice on a loaded machine).
constexpr std::int64_t kMaxStepsPerLock = 100;

}  // namespace

TwinService::TwinService(const TwinConfig& config, std::vector<drivers::DeviceProfile> profiles)
    // signals_ reads the profiles before server_ (declared after it) takes them over.
    : twin_(config), signals_(twin_, profiles), server_(std::move(profiles), signals_) {}

TwinService::~TwinService() { stop(); }

std::size_t TwinService::handle(std::uint8_t unit_id, std::span<const std::uint8_t> request,
                                std::span<std::uint8_t> reply) {
  std::lock_guard lock(mutex_);
  return server_.handle(unit_id, request, reply);
}

bool TwinService::serves(std::uint8_t unit_id) const { return server_.serves(unit_id); }

void TwinService::advance_to(double t_s) {
  std::lock_guard lock(mutex_);
  const double left = (t_s - twin_.time_s()) / twin_.step_s();
  if (left > 1e-9) signals_.advance(static_cast<std::int64_t>(std::ceil(left - 1e-9)));
}

double TwinService::time_s() const {
  std::lock_guard lock(mutex_);
  return twin_.time_s();
}

double TwinService::max_lag_s() const {
  std::lock_guard lock(mutex_);
  return max_lag_s_;
}

void TwinService::start_realtime(double time_scale) {
  stop();
  stop_ = false;
  thread_ = std::thread([this, time_scale] { run(time_scale); });
}

void TwinService::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void TwinService::run(double time_scale) {
  using clock = std::chrono::steady_clock;
  const auto wall0 = clock::now();
  double twin0 = 0, step = 0;
  {
    std::lock_guard lock(mutex_);
    twin0 = twin_.time_s();
    step = twin_.step_s();
  }
  // Wake once per chunk of twin time, but at least every millisecond of wall time.
  const auto period = std::chrono::duration<double>(std::min(1e-3, kChunkSteps * step / time_scale));
  auto wake = wall0;
  while (!stop_) {
    const double target = twin0 + time_scale * std::chrono::duration<double>(clock::now() - wall0).count();
    bool first = true;
    for (;;) {
      {
        std::lock_guard lock(mutex_);
        const auto due = static_cast<std::int64_t>(std::floor((target - twin_.time_s()) / step + 1e-9));
        if (due <= 0) break;
        // Behind schedule by more than one wake-up's worth: the CPU did not keep up.
        if (first) max_lag_s_ = std::max(max_lag_s_, static_cast<double>(due) * step - time_scale * period.count());
        first = false;
        signals_.advance(std::min(due, kMaxStepsPerLock));
      }
      if (stop_) break;
    }
    wake += std::chrono::duration_cast<clock::duration>(period);
    const auto now = clock::now();
    if (wake < now) wake = now;
    std::this_thread::sleep_until(wake);
  }
}

}  // namespace synbench::emulator
