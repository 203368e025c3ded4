// The twin as a Modbus device: the twin, its register map (TwinSignals behind a RegisterServer
// built from the device profiles) and one mutex that serializes requests against the
// simulation. Time advances either on request (virtual time, for the in-process bus) or on its
// own thread in real or scaled time (`synbench emulate`), in chunks of one millisecond of twin
// time, so a request waits at most one chunk.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <span>
#include <thread>
#include <vector>

#include "drivers/profile/device_profile.hpp"
#include "emulator/modbus/register_server.hpp"
#include "emulator/modbus/twin_signals.hpp"
#include "emulator/twin.hpp"

namespace synbench::emulator {

class TwinService {
 public:
  // `profiles`: one of each kind; the twin serves exactly these maps.
  TwinService(const TwinConfig& config, std::vector<drivers::DeviceProfile> profiles);
  ~TwinService();
  TwinService(const TwinService&) = delete;
  TwinService& operator=(const TwinService&) = delete;

  // One Modbus request PDU (see RegisterServer::handle); thread-safe.
  std::size_t handle(std::uint8_t unit_id, std::span<const std::uint8_t> request, std::span<std::uint8_t> reply);
  bool serves(std::uint8_t unit_id) const;

  // Virtual time: runs the twin until its time reaches t_s. Not while the real-time thread runs.
  void advance_to(double t_s);
  double time_s() const;

  // Real time: a thread keeps twin time = time_scale x wall time since the start.
  void start_realtime(double time_scale);
  void stop();
  // How far the twin fell behind its schedule at worst (the CPU did not keep up), s of twin time.
  double max_lag_s() const;

  // Anything else, under the service's lock: f(Twin&, TwinSignals&, RegisterServer&).
  template <class F>
  auto locked(F&& f) {
    std::lock_guard lock(mutex_);
    return f(twin_, signals_, server_);
  }

 private:
  void run(double time_scale);

  Twin twin_;
  TwinSignals signals_;
  RegisterServer server_;
  mutable std::mutex mutex_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  double max_lag_s_ = 0;  // under mutex_
};

}  // namespace synbench::emulator
