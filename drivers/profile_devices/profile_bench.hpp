// The bench's devices from three profiles and the buses that reach them: what `synbench point
// --bench` measures with, on hardware, on `synbench emulate` or on the in-process twin's
// register server. Its clock is the given one plus the watchdog heartbeats and the host-kept
// windows' samples: whenever the bench waits, the heartbeats and samples due meanwhile are
// taken, so logic never has to remember them.
#pragma once

#include <memory>

#include "drivers/clock.hpp"
#include "drivers/devices.hpp"
#include "drivers/profile_devices/profile_drives.hpp"
#include "drivers/profile_devices/window_trigger.hpp"

namespace synbench::drivers {

struct ProfileBenchOptions {
  double window_margin_s = 5.0;  // see ProfileWindowTrigger
  // Repeats of failed reads and idempotent writes (retry_policy.hpp), in the clock's time.
  RetryPolicy retry;
};

class ProfileBench {
 public:
  ProfileBench(RegisterBus& synrm_bus, DeviceProfile synrm, RegisterBus& load_bus, DeviceProfile load,
               RegisterBus& meter_bus, DeviceProfile meter, Clock& clock,
               const ProfileBenchOptions& options = {});
  ~ProfileBench();
  ProfileBench(const ProfileBench&) = delete;
  ProfileBench& operator=(const ProfileBench&) = delete;

  // No truth probe: only the in-process TwinBench can see the plant.
  BenchDevices devices();
  // The given clock; waiting on it keeps the heartbeats going.
  Clock& clock();
  // Takes the host-window samples due at `now_s`, and sends the heartbeats due (none while they
  // are stopped).
  void tick(double now_s);
  double next_heartbeat_s() const;
  // The next heartbeat, reset pulse end or host sample.
  double next_due_s() const;
  // Whether a drive's reset pulse is still held (tick() ends it).
  bool resets_pending() const { return synrm_.reset_pending() || load_.reset_pending(); }
  // Stops or resumes the heartbeats: stopped, the drives' watchdogs stop the drives on their own.
  void set_heartbeats(bool on) { heartbeats_ = on; }
  bool heartbeats() const { return heartbeats_; }

  ProfileSynrmDrive& synrm() { return synrm_; }
  ProfileLoadDrive& load() { return load_; }
  ProfileMeter& meter() { return meter_; }
  ProfileWindowTrigger& trigger() { return trigger_; }

 private:
  class HeartbeatClock;
  ProfileSynrmDrive synrm_;
  ProfileLoadDrive load_;
  ProfileMeter meter_;
  ProfileWindowTrigger trigger_;
  std::unique_ptr<HeartbeatClock> clock_;
  bool heartbeats_ = true;
};

}  // namespace synbench::drivers
