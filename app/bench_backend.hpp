// What a bench runs on, behind one interface (as ros2_control's hardware interface hides mock
// and real components): the in-process twin on its virtual clock, or the profile devices of a
// bench config over Modbus links on the wall clock. The daemon's runtime, `synbench sweep` and
// `synbench point` see only this; server/cli/bench_setup.* builds it from the command line.
#pragma once

#include <string>

#include "drivers/json.hpp"

#include "app/bench_description.hpp"
#include "drivers/clock.hpp"
#include "drivers/devices.hpp"

namespace synbench::app {

class BenchBackend {
 public:
  virtual ~BenchBackend() = default;
  virtual drivers::BenchDevices devices() = 0;
  // Waiting on it advances the twin, or keeps a real bench's heartbeats going.
  virtual drivers::Clock& clock() = 0;
  // Periodic link work due at `now_s` (the drives' watchdog heartbeats).
  virtual void tick(double /*now_s*/) {}
  // Whether tick() still has a command to finish (a reset pulse to end): a process that exits
  // right after a reset waits for it, or an edge-triggered drive's next reset is no edge.
  virtual bool ticks_pending() const { return false; }
  // Stops or resumes the heartbeats. An E-stop stops them, so that a drive the disable did not
  // reach is stopped by its own watchdog; they resume on a reset.
  // (A bench without a watchdog, the in-process twin, only keeps the flag.)
  virtual void set_heartbeats(bool on) { heartbeats_ = on; }
  virtual bool heartbeats() const { return heartbeats_; }
  // The devices as GET /api/devices shows them: [{"role", "kind", "backend", "link", "profile"}].
  virtual synbench::Json describe() const = 0;
  virtual const BenchDescription& description() const = 0;
  // The links in words, for messages: "tcp 127.0.0.1:1502", "twin (in-process)".
  virtual std::string links() const { return "twin (in-process)"; }
  // The last error of each link that had one, one per line ("" for the in-process twin).
  virtual std::string link_errors() const { return {}; }

 private:
  bool heartbeats_ = true;
};

}  // namespace synbench::app
