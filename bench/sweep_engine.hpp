// The sweep engine: runs a plan's points one after another on a running bench, unattended.
// Per point: command (chained on the running drives) -> settle (gate) -> thermal window ->
// measure (one window on every instrument) -> store (the sink commits it before the next point)
// -> next. Switching estimator or PWM scheme goes through an ordered stop, since the drive
// changes its position source only with the gates off. Adaptive plans search the MTPA and ME
// angles per curve instead of the full angle grid. The safety supervisor, ticked by the caller
// before the engine on every tick, has the last word: once it trips, the sweep is faulted.
// Pure logic on the time it is given; it never sleeps.
#pragma once

#include <cstddef>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "bench/ordered_stop.hpp"
#include "bench/point_procedure.hpp"
#include "bench/point_record.hpp"
#include "bench/safety_supervisor.hpp"
#include "bench/sweep_plan.hpp"
#include "drivers/devices.hpp"

namespace synbench::bench {

enum class SweepState { running, pausing, paused, stopping, completed, aborted, faulted };
std::string_view name(SweepState s);

struct SweepProgress {
  std::size_t done = 0;        // points stored, including those stored before a resume
  std::size_t total = 0;       // grid: all points; adaptive: an upper bound until searches end
  std::optional<std::size_t> current_index;
  double bench_elapsed_s = 0;  // since this run started
  std::optional<double> eta_s; // bench time still needed, from this run's pace
  SweepState state = SweepState::running;
};

// Where the engine's results go: a database in the CLI and the daemon, a vector in tests.
class SweepSink {
 public:
  virtual ~SweepSink() = default;
  // Called once per measured point; must make it durable before returning.
  virtual std::error_code store_point(std::size_t index, const PointRecord& record) = 0;
  // The sentence for store_point's last failure `ec`: a store knows more than its code (which
  // file, SQLite's own text), and the sweep faults with this.
  virtual std::string failure_message(std::error_code ec) const { return ec.message(); }
  virtual void event(const std::string& /*kind*/, const std::string& /*message*/) {}
  virtual void progress(const SweepProgress& /*p*/) {}
};

struct SweepBench {
  double load_b1_Nms_per_rad = 2.0e-4;  // the load machine's friction (bench calibration, 6.2)
  drivers::UncertaintyConfig uncertainty;  // the points' type B budget inputs
};

class SweepEngine {
 public:
  // `stored`: points already in the database for this sweep (a resume): never measured again;
  // in adaptive mode they are replayed into the searches so these continue where they stopped.
  SweepEngine(drivers::BenchDevices devices, const SafetySupervisor& supervisor, SweepPlan plan,
              std::map<std::size_t, PointRecord> stored, SweepSink& sink, SweepBench bench = {});
  ~SweepEngine();

  // Keeps only the groups (PlannedGroup::group) with group % count == index: one of `count`
  // engines that share the plan's groups out, each on a twin of its own (app/parallel_sweep.hpp).
  // Before the first tick only.
  void keep_groups(std::size_t index, std::size_t count);

  void tick(double now_s);
  // Pause: finish the point in flight, then hold the bench where it is. Resume continues.
  void pause();
  void resume();
  // Abort: drop the point in flight and bring the bench to its ordered stop. A reason (the
  // operator's words, "daemon stopped at ...") becomes the sweep's error (its last_error in the
  // store, named in the final event) with the state aborted.
  void abort(const std::string& reason = {});

  SweepState state() const { return state_; }
  bool finished() const;
  const std::string& error() const { return error_; }
  SweepProgress progress() const;
  // The request of the point under way (empty between points and once stopping).
  std::optional<PointRequest> current_request() const {
    return current_ ? std::optional<PointRequest>(current_->point.request) : std::nullopt;
  }

 private:
  struct Next {
    PlannedPoint point;
    std::optional<std::size_t> search;  // the adaptive search it belongs to
  };
  std::optional<Next> next_point();
  // `again`: the same point measured once more on the running bench (a precision target):
  // no least settling time, the gate alone decides.
  void start_point(const Next& n, double now_s, bool again = false);
  // A precision target the record misses: true when the point is being measured again (a longer
  // window); false when it is to be stored as it is (flagged when it missed the target).
  bool measure_again(const Next& n, const PointRecord& r);
  void finish_point(double now_s);
  // `coast`: once the load torque is gone, disable at once instead of commanding zero speed (a
  // drive that lost the rotor cannot be trusted to decelerate it).
  void begin_stop(SweepState final_state, double now_s, bool coast = false);
  void tick_stop(double now_s);

  drivers::BenchDevices dev_;
  const SafetySupervisor& sup_;
  SweepPlan plan_;
  std::map<std::size_t, PointRecord> stored_;
  SweepSink& sink_;
  SweepBench bench_;
  PointOptions options_;

  // Grid mode: the remaining points in order. Adaptive: groups and their searches.
  std::vector<PlannedPoint> grid_;
  std::size_t grid_pos_ = 0;
  std::vector<PlannedGroup> groups_;
  std::size_t group_pos_ = 0;
  std::vector<AngleSearch> searches_;

  SweepState state_ = SweepState::running;
  bool pause_requested_ = false, abort_requested_ = false;
  std::optional<Next> current_;
  std::unique_ptr<PointProcedure> proc_;
  std::optional<Configuration> running_config_;
  // The ordered stop between configurations or at the end.
  SweepState after_stop_ = SweepState::completed;
  OrderedStop stop_;
  double t0_ = -1, now_ = 0;
  std::size_t measured_this_run_ = 0;
  std::size_t remeasures_ = 0;  // windows after the first of the point under way
  std::string error_;
};

}  // namespace synbench::bench
