// The sweep engine's state machine.
#include "bench/sweep_engine.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bench/pace.hpp"
#include "bench/sweep_outcome.hpp"

namespace synbench::bench {
namespace {

constexpr double kStopLoadTimeout_s = 2.0;
constexpr double kStopSpeedTimeout_s = 20.0;
constexpr double kStoppedRpm = 20.0;

Configuration config_of(const PointRequest& r) { return Configuration{r.estimator, r.pwm}; }

}  // namespace

std::string_view name(SweepState s) {
  switch (s) {
    case SweepState::running: return "running";
    case SweepState::pausing: return "pausing";
    case SweepState::paused: return "paused";
    case SweepState::stopping: return "stopping";
    case SweepState::completed: return "completed";
    case SweepState::aborted: return "aborted";
    case SweepState::faulted: return "faulted";
  }
  return "unknown";
}

SweepEngine::SweepEngine(drivers::BenchDevices devices, const SafetySupervisor& supervisor,
                         SweepPlan plan, std::map<std::size_t, PointRecord> stored,
                         SweepSink& sink, SweepBench bench)
    : dev_(devices), sup_(supervisor), plan_(std::move(plan)), stored_(std::move(stored)),
      sink_(sink), bench_(bench) {
  options_ = point_options(plan_);
  options_.ordered_stop_after = false;
  options_.continue_running = true;
  options_.load_b1_Nms_per_rad = bench_.load_b1_Nms_per_rad;
  options_.uncertainty = bench_.uncertainty;
  if (plan_.thermal.enabled)
    options_.thermal = PointOptions::Thermal{plan_.thermal.target_C, plan_.thermal.band_C,
                                             plan_.thermal.warmup_load_Nm, plan_.thermal.timeout_s};
  if (plan_.mode == SweepMode::grid) {
    grid_ = expand(plan_);
  } else {
    // Replay what a previous run measured, so each search continues where it stopped.
    groups_ = plan_groups(plan_);
    for (const auto& g : groups_) searches_.push_back(replay_search(plan_, g, stored_));
  }
}

SweepEngine::~SweepEngine() = default;

void SweepEngine::keep_groups(std::size_t index, std::size_t count) {
  const auto mine = [&](std::size_t group) { return group % count == index; };
  std::erase_if(grid_, [&](const PlannedPoint& p) { return !mine(p.group); });
  std::vector<PlannedGroup> groups;
  std::vector<AngleSearch> searches;
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    if (!mine(groups_[g].group)) continue;
    groups.push_back(groups_[g]);
    searches.push_back(std::move(searches_[g]));
  }
  groups_ = std::move(groups);
  searches_ = std::move(searches);
}

bool SweepEngine::finished() const {
  return state_ == SweepState::completed || state_ == SweepState::aborted ||
         state_ == SweepState::faulted;
}

void SweepEngine::pause() {
  if (state_ == SweepState::running) {
    pause_requested_ = true;
    state_ = SweepState::pausing;
  }
}

void SweepEngine::resume() {
  pause_requested_ = false;
  if (state_ == SweepState::paused || state_ == SweepState::pausing) state_ = SweepState::running;
}

void SweepEngine::abort(const std::string& reason) {
  if (finished()) return;
  abort_requested_ = true;
  // The first reason stays: a shutdown after an operator's abort does not overwrite theirs.
  if (!reason.empty() && error_.empty()) error_ = reason;
}

std::optional<SweepEngine::Next> SweepEngine::next_point() {
  if (plan_.mode == SweepMode::grid) {
    while (grid_pos_ < grid_.size() && stored_.count(grid_[grid_pos_].index)) ++grid_pos_;
    if (grid_pos_ == grid_.size()) return std::nullopt;
    return Next{grid_[grid_pos_], std::nullopt};
  }
  for (; group_pos_ < groups_.size(); ++group_pos_) {
    const auto& search = searches_[group_pos_];
    if (const auto angle = search.next_angle()) {
      return Next{adaptive_point(plan_, groups_[group_pos_], search.evaluations().size(), *angle),
                  group_pos_};
    }
  }
  return std::nullopt;
}

void SweepEngine::start_point(const Next& n, double now_s, bool again) {
  current_ = n;
  if (!again) remeasures_ = 0;
  PointOptions options = options_;
  options.gate.average_s = gate_average_s(plan_, config_of(n.point.request));
  if (again) options.min_settle_s = 0;
  proc_ = std::make_unique<PointProcedure>(dev_, n.point.request, options);
  proc_->tick(now_s);
}

void SweepEngine::finish_point(double /*now_s*/) {
  const Next n = *current_;
  current_.reset();
  auto proc = std::move(proc_);
  if (!proc->has_record()) {
    // A device refused a command (the supervisor catches faults): nothing sensible to go on with.
    if (sup_.may_command()) {
      error_ = "point " + std::to_string(n.point.index) + ": " + proc->error();
      sink_.event("fault", error_);
      begin_stop(SweepState::faulted, now_);
    }
    return;
  }
  const PointRecord& r = proc->record();
  if (!proc->speed_lost() && measure_again(n, r)) return;
  if (const auto ec = sink_.store_point(n.point.index, r)) {
    error_ = "storing point " + std::to_string(n.point.index) + " failed: " + sink_.failure_message(ec);
    sink_.event("fault", error_);
    begin_stop(SweepState::faulted, now_);
    return;
  }
  stored_[n.point.index] = r;
  ++measured_this_run_;
  running_config_ = config_of(n.point.request);
  if (n.search) searches_[*n.search].report(r.angle_deg, r.im_A, r.pdcm_W, r.im_u_repeat_A, r.pdcm_u_repeat_W);
  if (plan_.mode == SweepMode::grid) ++grid_pos_;
  sink_.progress(progress());
  if (r.lock_lost) {
    // Not a fault: the estimator's limit at this point. The drive's lock guard already runs on
    // the encoder and hands back at the next point's setpoints.
    sink_.event("log", "point " + std::to_string(n.point.index) +
                           ": the estimator lost the rotor; the drive's lock guard ran the point "
                           "on the encoder");
  }
  if (r.angle_off) {
    // Stored (its powers are true for the angle it ran at), but a lab must not take it for the
    // requested angle: say so where the sweep's events are read.
    char what[200];
    std::snprintf(what, sizeof what,
                  "point %zu: the drive ran at a current angle of %.1f deg, not the requested %.1f deg "
                  "(angle_off)%s",
                  static_cast<std::size_t>(n.point.index), r.angle_meas_deg.value_or(0.0), r.angle_deg,
                  r.voltage_limited ? "; the window was voltage limited" : "");
    sink_.event("log", what);
  }
  if (proc->speed_lost()) {
    // The drive lost the speed (a sensorless observer that slipped off the rotor does not find
    // it again while the shaft stalls): ordered stop, and the next point starts from standstill.
    char what[160];
    std::snprintf(what, sizeof what,
                  "point %zu: the drive could not hold %.0f rpm (measured %.0f rpm); restarting "
                  "the drives for the next point",
                  static_cast<std::size_t>(n.point.index), r.speed_rpm, r.speed_meas_rpm);
    sink_.event("log", what);
    begin_stop(SweepState::running, now_, /*coast=*/true);
  }
}

bool SweepEngine::measure_again(const Next& n, const PointRecord& r) {
  if (!plan_.precision) return false;
  const PrecisionOptions& p = *plan_.precision;
  const double window_s = n.point.request.window_s;
  const auto u = r.pdcm_u_repeat_W;
  if (u && *u <= p.pdcm_u_repeat_target_W) return false;
  char what[300];
  if (u && remeasures_ < kMaxPrecisionRemeasures && window_s < p.max_window_s) {
    // Type A falls as window^-1/2 (batch means of a stationary signal): the window that reaches
    // the target, with a fifth to spare for the estimate's own scatter, at least half as long
    // again as this one, at most the cap; rounded up to the drive registers' 10 ms.
    const double ratio = *u / p.pdcm_u_repeat_target_W;
    const double predicted_s = 1.2 * window_s * ratio * ratio;
    const double next_s =
        std::min(p.max_window_s, std::ceil(std::max(predicted_s, 1.5 * window_s) * 100.0 - 1e-6) / 100.0);
    std::snprintf(what, sizeof what,
                  "point %zu: pdcm_u_repeat_W %.3g W above the target %.3g W over %.3g s; measuring again over "
                  "%.3g s",
                  static_cast<std::size_t>(n.point.index), *u, p.pdcm_u_repeat_target_W, window_s, next_s);
    sink_.event("log", what);
    Next again = n;
    again.point.request.window_s = next_s;
    ++remeasures_;
    start_point(again, now_, /*again=*/true);
    return true;
  }
  if (u) {
    std::snprintf(what, sizeof what,
                  "point %zu: precision target missed: pdcm_u_repeat_W %.3g W above the target %.3g W over "
                  "%.3g s (max_window_s %.3g s); stored as reached",
                  static_cast<std::size_t>(n.point.index), *u, p.pdcm_u_repeat_target_W, window_s, p.max_window_s);
  } else {
    std::snprintf(what, sizeof what,
                  "point %zu: precision target missed: no pdcm_u_repeat_W (no uncertainty budget); stored as "
                  "measured",
                  static_cast<std::size_t>(n.point.index));
  }
  sink_.event("log", what);
  return false;
}

void SweepEngine::begin_stop(SweepState final_state, double now_s, bool coast) {
  after_stop_ = final_state;
  if (final_state != SweepState::running) state_ = SweepState::stopping;
  // The load comes off at the bench's ramp, as between points: removed at the load drive's
  // 10 N m/s, it let the shaft run away from EEMF-LUT at 500 rpm, 76 deg into an over-speed
  // trip. A drive that lost the shaft (coast) has nothing to follow: off at once.
  OrderedStopOptions opt;
  opt.load_ramp_Nm_per_s = coast ? 0.0 : options_.load_ramp_Nm_per_s;
  opt.load_timeout_s = kStopLoadTimeout_s;
  opt.stopped_speed_rpm = kStoppedRpm;
  opt.speed_timeout_s = kStopSpeedTimeout_s;
  opt.coast = coast;
  const auto& lt = sup_.load();
  stop_.begin(dev_, opt, now_s, lt ? lt->torque_Nm : 0.0);
}

void SweepEngine::tick_stop(double now_s) {
  if (stop_.tick(now_s, sup_.synrm(), sup_.load())) {
    running_config_.reset();
    state_ = after_stop_;
    sink_.event("state", after_stop_ == SweepState::running
                             ? std::string("drives stopped to switch configuration")
                             : "sweep " + std::string(name(state_)));
    sink_.progress(progress());
  }
}

void SweepEngine::tick(double now_s) {
  now_ = now_s;
  if (t0_ < 0) t0_ = now_s;
  if (finished()) return;
  if (!sup_.may_command()) {
    // The supervisor has already brought the bench to its ordered stop.
    proc_.reset();
    current_.reset();
    stop_.cancel();
    state_ = SweepState::faulted;
    error_ = "safety supervisor tripped: " +
             (sup_.trip() ? std::string(drivers::fault_name(sup_.trip()->fault)) + " (" + sup_.trip()->detail + ")"
                          : std::string("unknown"));
    sink_.event("state", "sweep faulted: " + error_);
    sink_.progress(progress());
    return;
  }
  if (stop_.active()) return tick_stop(now_s);
  if (proc_) {
    if (abort_requested_) {
      proc_.reset();
      current_.reset();
      return begin_stop(SweepState::aborted, now_s);
    }
    proc_->tick(now_s);
    if (!proc_->finished()) return;
    finish_point(now_s);
    return;
  }
  if (abort_requested_) return begin_stop(SweepState::aborted, now_s);
  if (pause_requested_) {
    if (state_ != SweepState::paused) {
      state_ = SweepState::paused;
      sink_.event("state", "sweep paused");
      sink_.progress(progress());
    }
    return;
  }
  const auto n = next_point();
  if (!n) return begin_stop(SweepState::completed, now_s);
  if (running_config_ && *running_config_ != config_of(n->point.request))
    return begin_stop(SweepState::running, now_s);
  start_point(*n, now_s);
}

SweepProgress SweepEngine::progress() const {
  SweepProgress p;
  p.state = state_;
  p.done = stored_.size();
  if (plan_.mode == SweepMode::grid) {
    p.total = grid_.size();
  } else {
    for (std::size_t g = 0; g < searches_.size(); ++g)
      p.total += searches_[g].finished() ? searches_[g].evaluations().size()
                                          : plan_.adaptive.max_evaluations;
  }
  if (current_) p.current_index = current_->point.index;
  p.bench_elapsed_s = t0_ < 0 ? 0.0 : now_ - t0_;
  p.eta_s = remaining_s(p.bench_elapsed_s, measured_this_run_, p.done, p.total);
  return p;
}

}  // namespace synbench::bench
