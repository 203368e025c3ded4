// The bench thread and its command queue; see bench_runtime.hpp.
#include "app/bench_runtime.hpp"

#include <algorithm>

#include "app/plan_needs.hpp"
#include "bench/load_ramp.hpp"
#include "drivers/error.hpp"
#include "drivers/profile/number_format.hpp"

namespace synbench::app {

namespace {

Refusal device_error(const std::string& what, std::error_code ec) {
  return {Refused::device_error, what + ": " + ec.message()};
}

// The status as one sample of the telemetry history.
TelemetrySample history_sample(const BenchStatus& s) {
  TelemetrySample h;
  const auto f = [](double v) { return static_cast<float>(v); };
  h.t_s = s.t_s;
  if (s.synrm) {
    const auto& t = *s.synrm;
    h.speed_rpm = f(t.speed_rpm);
    h.im_A = f(t.im_A);
    h.id_A = f(t.id_A);
    h.iq_A = f(t.iq_A);
    h.udc_V = f(t.udc_V);
    h.pac_W = f(t.pac_W);
    if (t.temp_C) h.temp_C = f(*t.temp_C);
    if (t.pos_err_deg) h.pos_err_deg = f(*t.pos_err_deg);
  }
  if (s.load) h.torque_Nm = f(s.load->torque_Nm);
  h.cmd_speed_rpm = f(s.commanded.speed_rpm);
  h.cmd_load_Nm = f(s.commanded.load_Nm);
  h.cmd_angle_deg = f(s.commanded.angle_deg);
  h.enabled = (s.enabled || (s.sweep && s.sweep->current_index)) ? 1.0f : 0.0f;
  return h;
}

}  // namespace

BenchRuntime::BenchRuntime(std::unique_ptr<BenchBackend> backend, Serializer serializer, EventLog log)
    : backend_(std::move(backend)),
      description_(backend_->description()),
      devices_(backend_->describe()),
      serializer_(std::move(serializer)),
      log_(std::move(log)) {
  commanded_ = std::make_unique<CommandedDevices>(backend_->devices());
  supervisor_ = std::make_unique<bench::SafetySupervisor>(
      commanded_->devices(), description_.limits,
      [this](const std::string& kind, const std::string& message) { event(kind, message); });
  publish();
}

BenchRuntime::~BenchRuntime() { shutdown(std::chrono::milliseconds(2000)); }

void BenchRuntime::start() {
  std::lock_guard lock(shutdown_mutex_);
  if (thread_.joinable() || shut_down_) return;
  thread_ = std::thread([this] { run(); });
}

std::shared_ptr<const StatusSnapshot> BenchRuntime::snapshot() const {
  std::lock_guard lock(snapshot_mutex_);
  return snapshot_;
}

void BenchRuntime::submit(Act act, Done done, bool urgent) {
  std::optional<Refusal> refused;
  {
    std::lock_guard lock(queue_mutex_);
    // An E-stop is taken while the shutdown's ordered stop runs; nothing once the thread ended.
    if (closed_ || (!accepting_ && !urgent)) refused = Refusal{Refused::shutting_down, "the daemon is stopping"};
    else if (!urgent && queue_.size() >= kMaxQueued)
      refused = Refusal{Refused::queue_full, "more than " + std::to_string(kMaxQueued) + " commands wait for the bench"};
    else (urgent ? estops_ : queue_).push_back({std::move(act), std::move(done)});
  }
  if (refused) {
    if (done) done({std::move(refused), snapshot()});
    return;
  }
  wake_.notify_all();
}

bool BenchRuntime::estop_pending() const {
  std::lock_guard lock(queue_mutex_);
  return !estops_.empty();
}

void BenchRuntime::event(const std::string& kind, const std::string& message) {
  events_.push_back({backend_->clock().now_s(), kind, message, ++event_seq_});
  while (events_.size() > kMaxEvents) events_.pop_front();
  if (log_) log_(events_.back());
}

void BenchRuntime::run() {
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  const double base_s = backend_->clock().now_s();
  auto next = t0 + kTick;
  for (;;) {
    {
      std::unique_lock lock(queue_mutex_);
      wake_.wait_until(lock, next, [this] { return !estops_.empty() || !queue_.empty(); });
    }
    // E-stops before the clock's wait, which sends the heartbeats: on a dead line those alone
    // take seconds, and nothing goes on the link ahead of an E-stop's disables.
    if (estop_pending()) {
      auto estops = act_on_commands(backend_->clock().now_s(), /*estops_only=*/true);
      answer_estops(estops);
    }
    const double target_s = base_s + std::chrono::duration<double>(clock::now() - t0).count();
    // Waiting on the twin's clock advances the simulation to the wall clock.
    if (target_s > backend_->clock().now_s()) backend_->clock().wait_until(target_s);
    const double now_s = backend_->clock().now_s();
    auto answers = act_on_commands(now_s);
    answer_estops(answers);
    const bool due = clock::now() >= next;
    // A command is answered after a tick that read the drives back, not before.
    if (due || !answers.empty()) tick(now_s);
    publish();
    const auto snap = snapshot();
    for (auto& a : answers)
      if (a.done) a.done({std::move(a.refusal), snap});
    if (sweep_ && sweep_->finished()) {
      finish_sweep(now_s);
      publish();
    }
    if (due) {
      next += kTick;
      const auto now = clock::now();
      if (now > next + kTick) {
        ++overruns_;
        next = now + kTick;  // a stall is not made up in a burst
      }
    }
    if (quit_ && (settled() || clock::now() >= quit_deadline_)) {
      final_disable(now_s);
      break;
    }
  }
  // Whatever is still queued is answered: nobody waits for ever.
  std::deque<Command> left;
  {
    std::lock_guard lock(queue_mutex_);
    closed_ = true;
    left.swap(queue_);
    for (auto& c : estops_) left.push_back(std::move(c));
    estops_.clear();
  }
  const auto snap = snapshot();
  for (auto& c : left)
    if (c.done) c.done({Refusal{Refused::shutting_down, "the daemon is stopping"}, snap});
}

void BenchRuntime::answer_estops(std::vector<Answer>& answers) {
  // An E-stop is answered once both disables were tried, not after the tick's reads: on a
  // starved line those may take seconds, and its snapshot already says per drive whether the
  // disable was acknowledged or is being repeated (status.disable, until the read-back).
  const auto estops_end = std::stable_partition(answers.begin(), answers.end(), [](const Answer& a) { return a.estop; });
  if (estops_end == answers.begin()) return;
  publish();
  const auto snap = snapshot();
  for (auto it = answers.begin(); it != estops_end; ++it)
    if (it->done) it->done({std::move(it->refusal), snap});
  answers.erase(answers.begin(), estops_end);
}

std::vector<BenchRuntime::Answer> BenchRuntime::act_on_commands(double now_s, bool estops_only) {
  std::vector<Answer> answers;
  std::size_t budget;
  {
    std::lock_guard lock(queue_mutex_);
    budget = queue_.size();  // a flood of commands cannot keep the bench from its tick
  }
  for (;;) {
    Command c;
    bool urgent = false;
    {
      std::lock_guard lock(queue_mutex_);
      // An E-stop goes ahead of every command still queued.
      if (!estops_.empty()) {
        c = std::move(estops_.front());
        estops_.pop_front();
        urgent = true;
      } else if (!estops_only && budget > 0 && !queue_.empty()) {
        c = std::move(queue_.front());
        queue_.pop_front();
        --budget;
      } else {
        break;
      }
    }
    auto refusal = c.act(now_s);
    answers.push_back({std::move(c.done), std::move(refusal), urgent});
  }
  return answers;
}

void BenchRuntime::tick(double now_s) {
  ++ticks_;
  backend_->tick(now_s);
  if (estop_pending()) return;  // acted on at once, ahead of the reads
  supervisor_->tick(now_s);
  // An E-stop that arrived during the reads goes first: nothing else commands the drives.
  if (estop_pending()) return;
  if (sweep_) {
    // The engine reads the supervisor's verdict itself: a trip faults the sweep. Its end is
    // recorded after this tick's commands are answered (run()): an E-stop's answer never waits
    // for the store's commit.
    sweep_->tick(now_s);
    return;
  }
  if (supervisor_->tripped()) {
    // The supervisor runs its own ordered stop; ours is void.
    enabled_ = false;
    stop_.cancel();
    zero_held_setpoints();
    return;
  }
  if (stop_.tick(now_s, supervisor_->synrm(), supervisor_->load())) {
    event("stop", stop_.timed_out() ? "ordered stop timed out; drives disabled" : "ordered stop complete");
    supervisor_->expect_stopped(now_s);
  }
}

void BenchRuntime::publish() {
  auto snap = std::make_shared<StatusSnapshot>();
  BenchStatus& s = snap->status;
  s.t_s = backend_->clock().now_s();
  s.enabled = enabled_;
  s.stopping = stop_.active();
  s.heartbeats = backend_->heartbeats();
  s.setpoints = setpoints_;
  s.mode = mode_;
  s.synrm = supervisor_->synrm();
  s.load = supervisor_->load();
  s.synrm_error = supervisor_->synrm_read_error();
  s.load_error = supervisor_->load_read_error();
  s.phase = supervisor_->phase();
  s.trip = supervisor_->trip();
  s.alarm = supervisor_->alarm();
  s.disable = supervisor_->disable_report();
  const Commanded& c = commanded_->commanded();
  s.commanded = {c.speed_rpm.value_or(0.0), c.load_Nm.value_or(0.0), c.angle_deg.value_or(setpoints_.angle_deg)};
  s.ticks = ticks_;
  s.overruns = overruns_;
  s.events = events_;
  if (sweep_) {
    const auto p = sweep_->engine().progress();
    s.sweep = SweepInfo{sweep_->id(), std::string(bench::name(sweep_->engine().state())), p.done, p.total,
                        sweep_->engine().error(), p.current_index, sweep_->engine().current_request()};
  } else {
    s.sweep = last_sweep_;
  }
  if (serializer_) snap->text = serializer_(s);
  history_.offer(history_sample(s));
  std::lock_guard lock(snapshot_mutex_);
  snapshot_ = std::move(snap);
}

void BenchRuntime::do_estop(double now_s, const std::string& why) {
  // The heartbeats stop first: if a disable does not reach a drive, its watchdog still will.
  backend_->set_heartbeats(false);
  supervisor_->estop(now_s, why);
  enabled_ = false;
  stop_.cancel();
  zero_held_setpoints();
}

void BenchRuntime::zero_held_setpoints() {
  // After a stop nobody chose, the next Enable must not go straight back to the speed and load
  // the bench ran away at: an operator sets them again. The angle is no hazard at zero speed.
  if (setpoints_.speed_rpm == 0.0 && setpoints_.load_Nm == 0.0) return;
  setpoints_.speed_rpm = 0.0;
  setpoints_.load_Nm = 0.0;
  event("setpoints", "zeroed by the trip: speed 0 rpm, load 0 Nm, angle " + drivers::format_number(setpoints_.angle_deg) + " deg");
}

std::optional<Refusal> BenchRuntime::tripped_refusal() const {
  if (!supervisor_->tripped()) return std::nullopt;
  // In an operator's words (a dashboard shows it as it is): what tripped, and what to do.
  const auto& t = *supervisor_->trip();
  return Refusal{Refused::tripped, "the bench is tripped (" + std::string(drivers::fault_name(t.fault)) + ": " + t.detail +
                                       "): reset the trip first, once the cause is cleared"};
}

std::optional<Refusal> BenchRuntime::busy_with_sweep() const {
  if (!sweep_) return std::nullopt;
  return Refusal{Refused::sweep_running, "sweep " + std::to_string(sweep_->id()) + " drives the bench; abort it first"};
}

std::optional<Refusal> BenchRuntime::apply_setpoints() {
  auto dev = commanded_->devices();
  std::error_code ec;
  if ((ec = dev.synrm->set_angle_deg(setpoints_.angle_deg)) || (ec = dev.synrm->set_speed_rpm(setpoints_.speed_rpm)) ||
      (ec = dev.load->set_torque_Nm(setpoints_.load_Nm)))
    return device_error("the drive refused the setpoint", ec);
  return std::nullopt;
}

std::optional<Refusal> BenchRuntime::begin_disable(double now_s) {
  if (!enabled_ || stop_.active()) return std::nullopt;
  enabled_ = false;
  // At the bench's ramp, as a sweep's stop: a sensorless drive at a high current angle must
  // follow the acceleration.
  bench::OrderedStopOptions opt;
  opt.load_ramp_Nm_per_s = bench::kBenchLoadRamp_Nm_per_s;
  const auto& lt = supervisor_->load();
  stop_.begin(commanded_->devices(), opt, now_s, lt ? lt->torque_Nm : setpoints_.load_Nm);
  event("stop", "ordered stop requested");
  return std::nullopt;
}

void BenchRuntime::enable(bool on, Done done) {
  submit(
      [this, on](double now_s) -> std::optional<Refusal> {
        if (auto r = busy_with_sweep()) return r;
        if (!on) return begin_disable(now_s);
        if (auto r = tripped_refusal()) return r;
        if (supervisor_->alarm())
          return Refusal{Refused::drive_running, "alarm: " + supervisor_->alarm()->detail + "; reset first"};
        if (enabled_ && !stop_.active()) return std::nullopt;
        stop_.cancel();
        auto dev = commanded_->devices();
        std::error_code ec;
        if ((ec = dev.synrm->set_estimator(mode_.estimator)) || (ec = dev.synrm->set_pwm(mode_.pwm)))
          return device_error("setting the drive mode", ec);
        // As the point procedure: the load first, at zero torque, then the SynRM with its setpoints.
        std::optional<Refusal> failed;
        if ((ec = dev.load->set_torque_Nm(0.0)) || (ec = dev.load->enable(true)))
          failed = device_error("enabling the load drive", ec);
        if (!failed) failed = apply_setpoints();
        if (!failed && (ec = dev.synrm->enable(true))) failed = device_error("enabling the SynRM drive", ec);
        if (failed) {
          // Half a start is no state to leave a bench in: the supervisor disables both.
          supervisor_->expect_stopped(now_s);
          return failed;
        }
        enabled_ = true;
        event("enable", "drives enabled");
        return std::nullopt;
      },
      std::move(done));
}

void BenchRuntime::set_setpoints(SetpointsUpdate update, Done done) {
  submit(
      [this, update](double) -> std::optional<Refusal> {
        if (auto r = tripped_refusal()) return r;
        if (auto r = busy_with_sweep()) return r;
        if (update.speed_rpm) setpoints_.speed_rpm = *update.speed_rpm;
        if (update.load_Nm) setpoints_.load_Nm = *update.load_Nm;
        if (update.angle_deg) setpoints_.angle_deg = *update.angle_deg;
        event("setpoints", "speed " + drivers::format_number(setpoints_.speed_rpm) + " rpm, load " + drivers::format_number(setpoints_.load_Nm) + " Nm, angle " +
                               drivers::format_number(setpoints_.angle_deg) + " deg");
        if (enabled_ && !stop_.active()) return apply_setpoints();
        return std::nullopt;
      },
      std::move(done));
}

void BenchRuntime::set_mode(DriveModeUpdate update, Done done) {
  submit(
      [this, update](double) -> std::optional<Refusal> {
        if (auto r = busy_with_sweep()) return r;
        if (enabled_ || stop_.active())
          return Refusal{Refused::bench_enabled, "the drives are enabled; disable them before switching the estimator or PWM"};
        if (update.estimator) mode_.estimator = *update.estimator;
        if (update.pwm) mode_.pwm = *update.pwm;
        event("mode", "estimator " + std::string(drivers::name(mode_.estimator)) + ", pwm " + std::string(drivers::name(mode_.pwm)));
        return std::nullopt;
      },
      std::move(done));
}

void BenchRuntime::estop(std::string why, Done done) {
  submit(
      [this, why = std::move(why)](double now_s) -> std::optional<Refusal> {
        do_estop(now_s, why);
        return std::nullopt;
      },
      std::move(done), /*urgent=*/true);
}

void BenchRuntime::reset(Done done) {
  submit(
      [this](double now_s) -> std::optional<Refusal> {
        const bool paused = !backend_->heartbeats();
        // A fresh heartbeat before the faults are cleared, or a watchdog would trip again at once.
        backend_->set_heartbeats(true);
        backend_->tick(now_s);
        const auto ec = supervisor_->reset();
        if (!ec) return std::nullopt;
        if (paused) backend_->set_heartbeats(false);
        if (supervisor_->phase() == bench::SafetyPhase::stopping_load ||
            supervisor_->phase() == bench::SafetyPhase::stopping_speed)
          return Refusal{Refused::stop_in_progress, "reset refused: the ordered stop is still under way"};
        if (ec == errc::busy)
          return Refusal{Refused::drive_running, "reset refused: " + supervisor_->unconfirmed() +
                                                      (supervisor_->alarm() ? " (alarm: " + supervisor_->alarm()->detail + ")" : std::string())};
        return device_error("reset refused: clearing the drives' faults failed", ec);
      },
      std::move(done));
}

void BenchRuntime::start_sweep(std::int64_t id, bench::SweepPlan plan, std::map<std::size_t, bench::PointRecord> stored,
                               std::filesystem::path db_path, Done done) {
  auto shared = std::make_shared<std::pair<bench::SweepPlan, std::map<std::size_t, bench::PointRecord>>>(std::move(plan),
                                                                                                       std::move(stored));
  submit(
      [this, id, shared, db_path](double) -> std::optional<Refusal> {
        if (auto r = tripped_refusal()) return r;
        if (sweep_) return Refusal{Refused::sweep_running, "sweep " + std::to_string(sweep_->id()) + " is running"};
        if (enabled_ || stop_.active())
          return Refusal{Refused::bench_in_use, "the bench is enabled by hand; disable it first"};
        if (auto unmet = unmet_plan_needs(shared->first, description_)) return Refusal{Refused::invalid_state, *unmet};
        auto opened = db::Store::open(db_path);
        if (!opened) return Refusal{Refused::database, opened.error().message};
        sweep_store_ = std::make_unique<db::Store>(std::move(*opened));
        SweepRunOptions options;
        options.calibration.load_b1_Nms_per_rad = description_.load_b1_Nms_per_rad;
        options.calibration.uncertainty = description_.uncertainty;
        sweep_ = std::make_unique<SweepRun>(commanded_->devices(), *supervisor_, *sweep_store_, id, std::move(shared->first),
                                            std::move(shared->second), options);
        if (auto e = sweep_->begin()) {
          sweep_.reset();
          sweep_store_.reset();
          return Refusal{Refused::invalid_state, *e};
        }
        event("sweep", "sweep " + std::to_string(id) + " started");
        return std::nullopt;
      },
      std::move(done));
}

void BenchRuntime::sweep_action(std::int64_t id, std::string action, Done done, std::string reason) {
  submit(
      [this, id, action, reason](double) -> std::optional<Refusal> {
        if (!sweep_ || sweep_->id() != id)
          return Refusal{Refused::not_running, "sweep " + std::to_string(id) + " is not running on this bench"};
        if (action == "pause") sweep_->engine().pause();
        else if (action == "resume") sweep_->engine().resume();
        else sweep_->engine().abort(reason);
        event("sweep", "sweep " + std::to_string(id) + " " + action + (reason.empty() ? "" : ": " + reason));
        return std::nullopt;
      },
      std::move(done));
}

void BenchRuntime::finish_sweep(double now_s) {
  const auto p = sweep_->engine().progress();
  const auto state = sweep_->engine().state();
  const std::string& error = sweep_->engine().error();
  const std::string which = "sweep " + std::to_string(sweep_->id());
  last_sweep_ = SweepInfo{sweep_->id(), std::string(bench::name(state)), p.done, p.total, error, std::nullopt, std::nullopt};
  // A sweep's store failure (a lost file, a full disk) is a fault an operator must see in the
  // journal, with the store's message, as the supervisor's trips.
  if (auto e = sweep_->finish()) event("fault", which + ": recording its final state failed: " + *e);
  const bool faulted = state == bench::SweepState::faulted;
  event(faulted ? "fault" : "sweep", which + " " + std::string(bench::name(state)) + (error.empty() ? "" : ": " + error));
  sweep_.reset();
  sweep_store_.reset();
  if (!supervisor_->tripped()) supervisor_->expect_stopped(now_s);
}

bool BenchRuntime::settled() const {
  const auto ph = supervisor_->phase();
  return !sweep_ && !stop_.active() && ph != bench::SafetyPhase::stopping_load && ph != bench::SafetyPhase::stopping_speed;
}

void BenchRuntime::shutdown(std::chrono::milliseconds timeout) {
  {
    std::lock_guard lock(shutdown_mutex_);
    if (shut_down_) return;
    shut_down_ = true;
  }
  if (!thread_.joinable()) {
    // Never started: this thread is the devices' only user.
    {
      std::lock_guard lock(queue_mutex_);
      accepting_ = false;
      closed_ = true;
    }
    final_disable(backend_->clock().now_s());
    return;
  }
  {
    std::lock_guard lock(queue_mutex_);
    accepting_ = false;
    queue_.push_back({[this, timeout](double now_s) -> std::optional<Refusal> {
                        // A running sweep is aborted (its ordered stop, its state recorded);
                        // drives enabled by hand get the ordered stop.
                        if (sweep_) sweep_->engine().abort("daemon stopped at " + db::now_utc());
                        begin_disable(now_s);
                        quit_ = true;
                        quit_deadline_ = std::chrono::steady_clock::now() + timeout;
                        event("state", "shutdown: ordered stop");
                        return std::nullopt;
                      },
                      {}});
  }
  wake_.notify_all();
  thread_.join();
}

void BenchRuntime::final_disable(double now_s) {
  if (sweep_) finish_sweep(now_s);
  // The supervisor disables both (its events say which failed), reads them back and confirms
  // both stopped, or raises its alarm.
  supervisor_->expect_stopped(now_s);
  // As long as the supervisor's alarm may wait: the read-back plus each drive's own stop time.
  const double deadline_s = supervisor_->stop_deadline_s().value_or(now_s) + 0.05;
  double t = now_s;
  while (supervisor_->confirming_stop() && !supervisor_->alarm() && t < deadline_s) {
    t += kTick.count() / 1000.0;
    backend_->clock().wait_until(t);
    t = backend_->clock().now_s();
    supervisor_->tick(t);
  }
  if (!supervisor_->confirming_stop()) event("state", "shutdown: both drives read back disabled");
  backend_->set_heartbeats(false);
  publish();
}

}  // namespace synbench::app
