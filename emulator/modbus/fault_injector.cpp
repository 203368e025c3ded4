// Random fault decisions and the link cut.
#include "emulator/modbus/fault_injector.hpp"

namespace synbench::emulator {

FaultAction FaultInjector::decide() {
  std::lock_guard lock(mutex_);
  ++counts_.requests;
  const double x = std::uniform_real_distribution<double>(0.0, 100.0)(rng_);
  double edge = plan_.delay_pct;
  if (x < edge) {
    ++counts_.delayed;
    return FaultAction::delay;
  }
  edge += plan_.drop_pct;
  if (x < edge) {
    ++counts_.dropped;
    return FaultAction::drop;
  }
  edge += plan_.exception_pct;
  if (x < edge) {
    ++counts_.exceptions;
    return FaultAction::exception;
  }
  edge += plan_.corrupt_pct;
  if (x < edge) {
    ++counts_.corrupted;
    return FaultAction::corrupt;
  }
  return FaultAction::none;
}

void FaultInjector::cut_link(double seconds) {
  std::lock_guard lock(mutex_);
  ++counts_.cuts;
  cut_until_ = std::chrono::steady_clock::now() +
               std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
}

bool FaultInjector::link_cut() const {
  std::lock_guard lock(mutex_);
  return std::chrono::steady_clock::now() < cut_until_;
}

void FaultInjector::count_ignored_during_cut() {
  std::lock_guard lock(mutex_);
  ++counts_.ignored_during_cut;
}

FaultCounts FaultInjector::counts() const {
  std::lock_guard lock(mutex_);
  return counts_;
}

}  // namespace synbench::emulator
