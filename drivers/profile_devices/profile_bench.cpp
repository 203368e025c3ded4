// Profile devices assembled into a bench, and the clock that keeps their heartbeats.
#include "drivers/profile_devices/profile_bench.hpp"

#include <algorithm>
#include <limits>

namespace synbench::drivers {

class ProfileBench::HeartbeatClock final : public Clock {
 public:
  HeartbeatClock(ProfileBench& bench, Clock& base) : bench_(bench), base_(base) {}
  double now_s() const override { return base_.now_s(); }
  void wait_until(double t_s) override {
    for (;;) {
      const double now = base_.now_s();
      bench_.tick(now);
      // Within a microsecond counts as reached: a virtual clock moves in whole periods and
      // stops as close to t_s as they allow.
      if (now >= t_s - 1e-6) return;
      // Wake for the next heartbeat or host sample, never for less than a microsecond of progress.
      base_.wait_until(std::min(t_s, std::max(bench_.next_due_s(), now + 1e-6)));
    }
  }

 private:
  ProfileBench& bench_;
  Clock& base_;
};

ProfileBench::ProfileBench(RegisterBus& synrm_bus, DeviceProfile synrm, RegisterBus& load_bus,
                           DeviceProfile load, RegisterBus& meter_bus, DeviceProfile meter, Clock& clock,
                           const ProfileBenchOptions& options)
    : synrm_(synrm_bus, std::move(synrm)),
      load_(load_bus, std::move(load)),
      meter_(meter_bus, std::move(meter)),
      trigger_({&synrm_.window_source(), &load_.window_source(), &meter_.window_source()}, clock,
               options.window_margin_s),
      clock_(std::make_unique<HeartbeatClock>(*this, clock)) {
  for (ProfileDevice* d : {static_cast<ProfileDevice*>(&synrm_), static_cast<ProfileDevice*>(&load_),
                           static_cast<ProfileDevice*>(&meter_)})
    d->io().set_retry_policy(options.retry, &clock);
}

ProfileBench::~ProfileBench() = default;

BenchDevices ProfileBench::devices() { return {&synrm_, &load_, &meter_, &trigger_, nullptr}; }

Clock& ProfileBench::clock() { return *clock_; }

void ProfileBench::tick(double now_s) {
  // Host windows sample on their grid, and a reset pulse ends on time, also with the heartbeats
  // stopped.
  trigger_.tick(now_s);
  synrm_.tick(now_s, heartbeats_);
  load_.tick(now_s, heartbeats_);
  meter_.tick(now_s, heartbeats_);
}

double ProfileBench::next_due_s() const { return std::min(next_heartbeat_s(), trigger_.next_due_s()); }

double ProfileBench::next_heartbeat_s() const {
  return std::min({synrm_.next_heartbeat_s(heartbeats_), load_.next_heartbeat_s(heartbeats_),
                   meter_.next_heartbeat_s(heartbeats_)});
}

}  // namespace synbench::drivers
