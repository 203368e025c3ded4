// The daemon's bench: the in-process twin (or a real bench through a BenchBackend) run in real
// time on a thread of its own. Every 10 ms the bench clock is advanced to the wall clock's
// elapsed time (the twin's virtual clock is made to follow it) and the safety supervisor ticked; HTTP handlers reach the bench only through this class, whose mutex they
// share with the bench thread for the few microseconds a command or a status read takes.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include <filesystem>
#include <map>

#include "bench/ordered_stop.hpp"
#include "bench/safety_supervisor.hpp"
#include "bench/sweep_engine.hpp"
#include "db/store.hpp"
#include "emulator/twin_config.hpp"
#include "server/http/bench_backend.hpp"

namespace synbench::http {

struct Setpoints {
  double speed_rpm = 0;
  double load_Nm = 0;
  double angle_deg = 45;
};

// The drive configuration manual operation runs with (a sweep sets its own per point).
struct DriveMode {
  drivers::Estimator estimator = drivers::Estimator::encoder;
  drivers::Pwm pwm = drivers::Pwm::capwm;
};

struct BenchEvent {
  double t_s = 0;
  std::string kind, message;
  std::uint64_t seq = 0;  // 1, 2, 3, ... in order of occurrence: the WebSocket hub sends each once
};

// The sweep the bench thread runs (or ran last).
struct SweepRun {
  std::int64_t id = 0;
  std::string state;  // bench::SweepState's name
  std::size_t done = 0, total = 0;
  std::string error;
};

struct BenchStatus {
  double t_s = 0;  // bench time since start
  bool enabled = false;
  bool stopping = false;  // an ordered stop asked for by disable or shutdown is under way
  Setpoints setpoints;
  DriveMode mode;
  std::optional<drivers::SynrmTelemetry> synrm;
  std::optional<drivers::LoadTelemetry> load;
  bench::SafetyPhase phase = bench::SafetyPhase::normal;
  std::optional<bench::SafetyTrip> trip;
  std::uint64_t ticks = 0;
  std::uint64_t overruns = 0;  // ticks that started more than one period late
  std::deque<BenchEvent> events;  // the most recent supervisor and command events
  std::optional<SweepRun> sweep;
};

// Why a command was refused: an HTTP status, a stable code and a sentence.
struct Refusal {
  int status = 409;
  std::string code, message;
};

class BenchRuntime {
 public:
  static constexpr std::chrono::milliseconds kTick{10};
  static constexpr std::size_t kMaxEvents = 50;

  // On the in-process twin.
  BenchRuntime(const emulator::TwinConfig& config, bench::SafetyLimits limits);
  // On `backend`; `config` still gives the machine's limits the setpoints are checked against.
  BenchRuntime(const emulator::TwinConfig& config, bench::SafetyLimits limits, std::unique_ptr<BenchBackend> backend);
  ~BenchRuntime();
  BenchRuntime(const BenchRuntime&) = delete;
  BenchRuntime& operator=(const BenchRuntime&) = delete;

  void start();
  // The ordered stop (load torque to zero, speed to zero, drives disabled), waiting up to
  // `timeout` of wall time for it, then the bench thread ends. Idempotent.
  void shutdown(std::chrono::milliseconds timeout = std::chrono::milliseconds(15000));

  BenchStatus status() const;
  const emulator::TwinConfig& config() const { return config_; }
  nlohmann::json describe_devices() const;

  // Enabling starts both drives with the current setpoints; disabling is the ordered stop.
  std::optional<Refusal> enable(bool on);
  // Applied at once when enabled, kept for the next enable otherwise. Values are validated by
  // the caller (the REST handler names the field); refused while the supervisor is tripped.
  std::optional<Refusal> set_setpoints(const Setpoints& sp);
  // Position source and switching scheme for manual operation; refused while the drives are
  // enabled (the firmware switches only when stopped, as the sweep engine does) or a sweep runs.
  std::optional<Refusal> set_mode(const DriveMode& mode);
  void estop();
  std::optional<Refusal> reset();

  // Runs sweep `id` of the store at `db_path` on the bench thread (its own connection there),
  // skipping `stored` points; refused while the bench is enabled by hand, tripped or busy.
  std::optional<Refusal> start_sweep(std::int64_t id, bench::SweepPlan plan,
                                     std::map<std::size_t, bench::PointRecord> stored, const std::filesystem::path& db_path);
  // "pause", "resume" or "abort" of the running sweep `id`.
  std::optional<Refusal> sweep_action(std::int64_t id, const std::string& action);

 private:
  class Sink;
  void finish_sweep_locked();
  void run();
  void tick_locked(double now_s);
  void event_locked(const std::string& kind, const std::string& message);
  std::optional<Refusal> apply_locked();

  emulator::TwinConfig config_;
  std::unique_ptr<BenchBackend> backend_;
  std::unique_ptr<bench::SafetySupervisor> supervisor_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool quit_ = false;
  bool enabled_ = false;
  bench::OrderedStop stop_;  // a user's disable or a shutdown
  Setpoints setpoints_;
  DriveMode mode_;
  std::uint64_t ticks_ = 0, overruns_ = 0;
  std::uint64_t event_seq_ = 0;  // seq of the last event
  std::deque<BenchEvent> events_;
  std::unique_ptr<db::Store> sweep_store_;
  std::unique_ptr<Sink> sink_;
  std::unique_ptr<bench::SweepEngine> engine_;
  std::int64_t sweep_id_ = 0;
  bool sweep_sparse_ = false;
  std::optional<SweepRun> last_sweep_;
  std::thread thread_;
  bool shut_down_ = false;
};

}  // namespace synbench::http
