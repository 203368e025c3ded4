// The bench run in real time on a thread of its own, the one owner of the devices. Every 10 ms
// it advances the bench clock to the wall clock (the twin's virtual clock follows it), ticks the
// safety supervisor and a running sweep, and publishes an immutable status snapshot. Nothing else
// touches a device: commands (enable, setpoints, mode, reset, sweeps) are messages queued to the
// bench thread, acted on there, and answered through their callback once acted on. An E-stop
// goes ahead of everything queued and wakes the thread at once: it stops the watchdog heartbeats
// (so the drives' own watchdogs are the second line), disables both drives (each request once)
// and is answered right then, before the tick's reads: its snapshot says what each drive made of
// its disable (status.disable), and the supervisor repeats it every tick until both read back
// stopped, latching an alarm if one still runs. Free of HTTP and of the twin.
#pragma once

#include "drivers/json.hpp"

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "app/bench_backend.hpp"
#include "app/bench_status.hpp"
#include "app/commanded_devices.hpp"
#include "app/refusal.hpp"
#include "app/telemetry_history.hpp"
#include "app/sweep_run.hpp"
#include "bench/ordered_stop.hpp"
#include "bench/safety_supervisor.hpp"
#include "db/store.hpp"

namespace synbench::app {

// What the bench thread publishes each tick: the status, and its text as the API serves it,
// made once for every reader.
struct StatusSnapshot {
  BenchStatus status;
  std::string text;
};

// A command's answer: refused (and why), or done; with the snapshot taken after it was acted on.
struct Outcome {
  std::optional<Refusal> refusal;
  std::shared_ptr<const StatusSnapshot> snapshot;
};

class BenchRuntime {
 public:
  static constexpr std::chrono::milliseconds kTick{10};
  static constexpr std::size_t kMaxEvents = 50;
  static constexpr std::size_t kMaxQueued = 64;  // commands waiting; more are refused at once

  using Done = std::function<void(Outcome)>;
  // Called on the bench thread: the snapshot's text, and every event (a log, a journal).
  using Serializer = std::function<std::string(const BenchStatus&)>;
  using EventLog = std::function<void(const BenchEvent&)>;

  explicit BenchRuntime(std::unique_ptr<BenchBackend> backend, Serializer serializer = {}, EventLog log = {});
  ~BenchRuntime();
  BenchRuntime(const BenchRuntime&) = delete;
  BenchRuntime& operator=(const BenchRuntime&) = delete;

  void start();
  // The ordered stop through the bench thread (a running sweep aborted, load torque to zero,
  // speed to zero, both drives disabled and read back), waiting up to `timeout` of wall time for
  // it; then both drives are disabled regardless, the heartbeats stop and the thread ends. Every
  // command still queued is answered shutting_down. Idempotent; blocks the caller.
  void shutdown(std::chrono::milliseconds timeout = std::chrono::milliseconds(15000));

  // The latest snapshot; never waits on the bench thread's device I/O.
  std::shared_ptr<const StatusSnapshot> snapshot() const;
  const BenchDescription& description() const { return description_; }
  const synbench::Json& devices_json() const { return devices_; }
  // The telemetry of the last 15 min, a sample per 50 ms of bench time (offered every tick).
  TelemetryHistory& history() { return history_; }
  const TelemetryHistory& history() const { return history_; }

  // Commands. `done` is called on the bench thread once the command was acted on or refused.
  // Enabling starts both drives with the current setpoints; disabling is the ordered stop.
  void enable(bool on, Done done);
  // Applied at once when enabled, kept for the next enable otherwise; values are validated by
  // the caller against description(). Refused while tripped or a sweep runs.
  void set_setpoints(SetpointsUpdate update, Done done);
  // Position source and PWM for manual operation; refused while the drives run or a sweep runs.
  void set_mode(DriveModeUpdate update, Done done);
  // Pre-empts everything queued; latched until reset. The held speed and load setpoints are
  // zeroed (as on any latched trip): Enable after the reset starts at 0 rpm, 0 N m.
  void estop(std::string why, Done done);
  // Clears the latched trip and the drives' faults; resumes the heartbeats.
  void reset(Done done);
  // Runs sweep `id` of the store at `db_path` (its own connection on the bench thread),
  // skipping `stored` points; refused while the bench is enabled by hand, tripped or busy.
  void start_sweep(std::int64_t id, bench::SweepPlan plan, std::map<std::size_t, bench::PointRecord> stored,
                   std::filesystem::path db_path, Done done);
  // "pause", "resume" or "abort" of the running sweep `id`; an abort's reason (may be empty) is
  // stored with the sweep as its error and named in the event.
  void sweep_action(std::int64_t id, std::string action, Done done, std::string reason = {});

 private:
  using Act = std::function<std::optional<Refusal>(double now_s)>;
  struct Command {
    Act act;
    Done done;
  };
  void submit(Act act, Done done, bool urgent = false);
  void run();
  struct Answer {
    Done done;
    std::optional<Refusal> refusal;
    bool estop = false;
  };
  // Takes the queued commands (E-stops first; only those when `estops_only`) and acts on each;
  // returns them for their answer.
  std::vector<Answer> act_on_commands(double now_s, bool estops_only = false);
  // Answers the E-stops among `answers` now, with a fresh snapshot, and removes them.
  void answer_estops(std::vector<Answer>& answers);
  void tick(double now_s);
  void publish();
  void event(const std::string& kind, const std::string& message);
  bool estop_pending() const;
  void do_estop(double now_s, const std::string& why);
  // Speed and load setpoints held for the next enable to 0 (an E-stop, any latched trip).
  void zero_held_setpoints();
  std::optional<Refusal> apply_setpoints();
  std::optional<Refusal> begin_disable(double now_s);
  std::optional<Refusal> busy_with_sweep() const;
  std::optional<Refusal> tripped_refusal() const;  // while the supervisor's trip latches
  void finish_sweep(double now_s);
  bool settled() const;
  void final_disable(double now_s);

  std::unique_ptr<BenchBackend> backend_;
  const BenchDescription description_;
  // The backend's devices as every command here reaches them: what was last written is recorded.
  std::unique_ptr<CommandedDevices> commanded_;
  const synbench::Json devices_;
  Serializer serializer_;
  EventLog log_;

  // Shared with other threads: the queue and the snapshot, each behind its own short lock.
  mutable std::mutex queue_mutex_;
  std::condition_variable wake_;
  std::deque<Command> queue_;
  std::deque<Command> estops_;
  bool accepting_ = true;  // false once shutdown began: commands but E-stops are refused
  bool closed_ = false;    // the bench thread has ended: everything is refused
  mutable std::mutex snapshot_mutex_;
  std::shared_ptr<const StatusSnapshot> snapshot_;
  TelemetryHistory history_;

  // The bench thread's own state: nobody else reads or writes it.
  std::unique_ptr<bench::SafetySupervisor> supervisor_;
  bool enabled_ = false;
  bool quit_ = false;  // the thread ends once the shutdown's stop has settled, or at the deadline
  std::chrono::steady_clock::time_point quit_deadline_;
  bench::OrderedStop stop_;  // a user's disable or a shutdown
  Setpoints setpoints_;
  DriveMode mode_;
  std::uint64_t ticks_ = 0, overruns_ = 0;
  std::uint64_t event_seq_ = 0;
  std::deque<BenchEvent> events_;
  std::unique_ptr<db::Store> sweep_store_;
  std::unique_ptr<SweepRun> sweep_;
  std::optional<SweepInfo> last_sweep_;
  std::thread thread_;
  std::mutex shutdown_mutex_;
  bool shut_down_ = false;
};

}  // namespace synbench::app
