// The twin behind the bench's typed device interfaces, with a virtual clock whose waiting
// advances the simulation: the same bench code runs on it as on real drives.
#pragma once

#include <memory>

#include "drivers/clock.hpp"
#include "drivers/devices.hpp"
#include "emulator/twin.hpp"

namespace synbench::emulator {

class TwinBench {
 public:
  explicit TwinBench(const TwinConfig& config);
  ~TwinBench();
  TwinBench(const TwinBench&) = delete;
  TwinBench& operator=(const TwinBench&) = delete;

  Twin& twin() { return twin_; }
  drivers::BenchDevices devices();
  drivers::Clock& clock();

  // Cuts (or restores) the link to every device: calls fail with errc::disconnected, and after
  // `watchdog_timeout_s` of silence both drives stop on their own watchdog and latch it, as the
  // firmware behind a real link does.
  void set_link_down(bool down);
  bool link_down() const;
  static constexpr double kWatchdogTimeout_s = 0.5;

 private:
  struct Adapters;
  Twin twin_;
  std::unique_ptr<Adapters> adapters_;
};

}  // namespace synbench::emulator
