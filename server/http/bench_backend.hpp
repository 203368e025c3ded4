// What the daemon's bench runs on, behind one interface (as ros2_control's hardware interface
// hides mock and real components): the in-process twin on its virtual clock, or the profile
// devices of a bench config over Modbus links on the wall clock. BenchRuntime sees only this.
#pragma once

#include <memory>

#include <nlohmann/json.hpp>

#include "drivers/clock.hpp"
#include "drivers/devices.hpp"
#include "emulator/twin_config.hpp"

namespace synbench::http {

class BenchBackend {
 public:
  virtual ~BenchBackend() = default;
  virtual drivers::BenchDevices devices() = 0;
  // Waiting on it advances the twin, or keeps a real bench's heartbeats going.
  virtual drivers::Clock& clock() = 0;
  // Called every bench tick: heartbeats and other periodic link work due at `now_s`.
  virtual void tick(double /*now_s*/) {}
  // The devices as GET /api/devices shows them: [{"role", "kind", "backend", "link", "profile"}].
  virtual nlohmann::json describe() const = 0;
  // Viscous friction of the load machine, which the sweep engine uses to compute the shaft power.
  virtual double load_b1_Nms_per_rad() const = 0;
};

// The in-process twin (emulator::TwinBench), its virtual clock advanced by the runtime.
std::unique_ptr<BenchBackend> make_twin_backend(const emulator::TwinConfig& config);

}  // namespace synbench::http
