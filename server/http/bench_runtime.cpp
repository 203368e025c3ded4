// The real-time bench thread; see bench_runtime.hpp.
#include "server/http/bench_runtime.hpp"

#include <cmath>
#include <sstream>

#include "bench/load_ramp.hpp"

namespace synbench::http {

namespace {

std::string fmt(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}
}  // namespace

// Points go to the database, one committed transaction each, as in `synbench sweep`.
class BenchRuntime::Sink final : public bench::SweepSink {
 public:
  Sink(db::Store& store, std::int64_t id) : store_(store), id_(id) {}
  std::error_code store_point(std::size_t index, const bench::PointRecord& r) override {
    return store_.insert_point(id_, static_cast<std::int64_t>(index), r).code();
  }
  void event(const std::string& kind, const std::string& message) override {
    const auto k = kind == "fault" ? db::EventKind::fault : kind == "state" ? db::EventKind::state : db::EventKind::log;
    (void)store_.add_event(id_, k, message);
  }

 private:
  db::Store& store_;
  std::int64_t id_;
};

BenchRuntime::BenchRuntime(const emulator::TwinConfig& config, bench::SafetyLimits limits)
    : BenchRuntime(config, limits, make_twin_backend(config)) {}

BenchRuntime::BenchRuntime(const emulator::TwinConfig& config, bench::SafetyLimits limits, std::unique_ptr<BenchBackend> backend)
    : config_(config), backend_(std::move(backend)) {
  // The sink runs inside supervisor_->tick/estop/reset, always under mutex_.
  supervisor_ = std::make_unique<bench::SafetySupervisor>(
      backend_->devices(), limits, [this](const std::string& kind, const std::string& message) { event_locked(kind, message); });
}

BenchRuntime::~BenchRuntime() { shutdown(std::chrono::milliseconds(2000)); }

void BenchRuntime::start() {
  std::lock_guard lock(mutex_);
  if (thread_.joinable() || shut_down_) return;
  thread_ = std::thread([this] { run(); });
}

void BenchRuntime::event_locked(const std::string& kind, const std::string& message) {
  events_.push_back({backend_->clock().now_s(), kind, message, ++event_seq_});
  while (events_.size() > kMaxEvents) events_.pop_front();
}

void BenchRuntime::run() {
  using clock = std::chrono::steady_clock;
  std::unique_lock lock(mutex_);
  const auto t0 = clock::now();
  const double base_s = backend_->clock().now_s();
  auto next = t0;
  while (!quit_) {
    const double target_s = base_s + std::chrono::duration<double>(clock::now() - t0).count();
    // Waiting on the twin's clock advances the simulation to the wall clock.
    if (target_s > backend_->clock().now_s()) backend_->clock().wait_until(target_s);
    tick_locked(backend_->clock().now_s());
    next += kTick;
    const auto now = clock::now();
    if (now > next + kTick) {
      ++overruns_;
      next = now;  // a stall is not made up in a burst
    }
    wake_.wait_until(lock, next, [this] { return quit_; });
  }
}

nlohmann::json BenchRuntime::describe_devices() const {
  std::lock_guard lock(mutex_);
  return backend_->describe();
}

void BenchRuntime::tick_locked(double now_s) {
  ++ticks_;
  backend_->tick(now_s);
  supervisor_->tick(now_s);
  if (engine_) {
    // The engine reads the supervisor's verdict itself: a trip faults the sweep.
    engine_->tick(now_s);
    if (engine_->finished()) finish_sweep_locked();
    return;
  }
  if (supervisor_->tripped()) {
    // The supervisor runs its own ordered stop; ours is void.
    enabled_ = false;
    stop_.cancel();
    return;
  }
  if (stop_.tick(now_s, supervisor_->synrm(), supervisor_->load()))
    event_locked("stop", stop_.timed_out() ? "ordered stop timed out; drives disabled" : "ordered stop complete");
}

void BenchRuntime::finish_sweep_locked() {
  const auto st = engine_->state();
  const auto final_state = st == bench::SweepState::completed ? db::SweepState::completed
                           : st == bench::SweepState::aborted ? db::SweepState::aborted
                                                              : db::SweepState::faulted;
  std::optional<std::string> err;
  if (!engine_->error().empty()) err = engine_->error();
  const auto p = engine_->progress();
  last_sweep_ = SweepRun{sweep_id_, std::string(bench::name(st)), p.done, p.total, engine_->error()};
  if (auto r = sweep_store_->set_sweep_state(sweep_id_, final_state, err, sweep_sparse_); !r)
    event_locked("sweep", "recording the final state failed: " + r.error().message);
  event_locked("sweep", "sweep " + std::to_string(sweep_id_) + " " + std::string(bench::name(st)));
  engine_.reset();
  sink_.reset();
  sweep_store_.reset();
}

std::optional<Refusal> BenchRuntime::start_sweep(std::int64_t id, bench::SweepPlan plan,
                                                 std::map<std::size_t, bench::PointRecord> stored,
                                                 const std::filesystem::path& db_path) {
  std::lock_guard lock(mutex_);
  if (shut_down_) return Refusal{503, "shutting_down", "the daemon is stopping"};
  if (supervisor_->tripped())
    return Refusal{409, "tripped", "the safety supervisor has tripped; POST /api/bench/reset first"};
  if (engine_) return Refusal{409, "sweep_running", "sweep " + std::to_string(sweep_id_) + " is running"};
  if (enabled_ || stop_.active()) return Refusal{409, "bench_in_use", "the bench is enabled by hand; disable it first"};
  auto opened = db::Store::open(db_path);
  if (!opened) return Refusal{500, "database", opened.error().message};
  sweep_store_ = std::make_unique<db::Store>(std::move(*opened));
  if (auto r = sweep_store_->set_sweep_state(id, db::SweepState::running); !r) {
    sweep_store_.reset();
    return Refusal{409, "invalid_state", r.error().message};
  }
  sweep_id_ = id;
  sweep_sparse_ = plan.mode == bench::SweepMode::adaptive;
  sink_ = std::make_unique<Sink>(*sweep_store_, id);
  bench::SweepBench cal;
  cal.load_b1_Nms_per_rad = backend_->load_b1_Nms_per_rad();
  engine_ = std::make_unique<bench::SweepEngine>(backend_->devices(), *supervisor_, std::move(plan), std::move(stored), *sink_, cal);
  event_locked("sweep", "sweep " + std::to_string(id) + " started");
  return std::nullopt;
}

std::optional<Refusal> BenchRuntime::sweep_action(std::int64_t id, const std::string& action) {
  std::lock_guard lock(mutex_);
  if (!engine_ || sweep_id_ != id)
    return Refusal{409, "not_running", "sweep " + std::to_string(id) + " is not running on this bench"};
  if (action == "pause") engine_->pause();
  else if (action == "resume") engine_->resume();
  else engine_->abort();
  event_locked("sweep", "sweep " + std::to_string(id) + " " + action);
  return std::nullopt;
}

std::optional<Refusal> BenchRuntime::apply_locked() {
  auto dev = backend_->devices();
  std::error_code ec;
  if ((ec = dev.synrm->set_angle_deg(setpoints_.angle_deg)) || (ec = dev.synrm->set_speed_rpm(setpoints_.speed_rpm)) ||
      (ec = dev.load->set_torque_Nm(setpoints_.load_Nm)))
    return Refusal{502, "device_error", "the drive refused the setpoint: " + ec.message()};
  return std::nullopt;
}

std::optional<Refusal> BenchRuntime::enable(bool on) {
  std::lock_guard lock(mutex_);
  auto dev = backend_->devices();
  if (engine_) return Refusal{409, "sweep_running", "sweep " + std::to_string(sweep_id_) + " drives the bench; abort it first"};
  if (on) {
    if (supervisor_->tripped())
      return Refusal{409, "tripped", "the safety supervisor has tripped; POST /api/bench/reset first"};
    if (enabled_ && !stop_.active()) return std::nullopt;
    stop_.cancel();
    std::error_code ec;
    if ((ec = dev.synrm->set_estimator(mode_.estimator)) || (ec = dev.synrm->set_pwm(mode_.pwm)))
      return Refusal{502, "device_error", "setting the drive mode: " + ec.message()};
    // As the point procedure: the load first, at zero torque, then the SynRM with its setpoints.
    if ((ec = dev.load->set_torque_Nm(0.0)) || (ec = dev.load->enable(true)))
      return Refusal{502, "device_error", "enabling the load drive: " + ec.message()};
    if (auto r = apply_locked()) return r;
    if ((ec = dev.synrm->enable(true))) return Refusal{502, "device_error", "enabling the SynRM drive: " + ec.message()};
    enabled_ = true;
    event_locked("enable", "drives enabled");
    return std::nullopt;
  }
  if (!enabled_ || stop_.active()) return std::nullopt;
  enabled_ = false;
  // At the bench's ramp, as a sweep's stop: a sensorless drive at a high current angle must
  // follow the acceleration.
  bench::OrderedStopOptions opt;
  opt.load_ramp_Nm_per_s = bench::kBenchLoadRamp_Nm_per_s;
  const auto& lt = supervisor_->load();
  stop_.begin(dev, opt, backend_->clock().now_s(), lt ? lt->torque_Nm : setpoints_.load_Nm);
  event_locked("stop", "ordered stop requested");
  return std::nullopt;
}

std::optional<Refusal> BenchRuntime::set_setpoints(const Setpoints& sp) {
  std::lock_guard lock(mutex_);
  if (supervisor_->tripped())
    return Refusal{409, "tripped", "the safety supervisor has tripped; POST /api/bench/reset first"};
  if (engine_) return Refusal{409, "sweep_running", "sweep " + std::to_string(sweep_id_) + " drives the bench; abort it first"};
  setpoints_ = sp;
  event_locked("setpoints", "speed " + fmt(sp.speed_rpm) + " rpm, load " + fmt(sp.load_Nm) + " Nm, angle " + fmt(sp.angle_deg) + " deg");
  if (enabled_ && !stop_.active()) return apply_locked();
  return std::nullopt;
}

std::optional<Refusal> BenchRuntime::set_mode(const DriveMode& mode) {
  std::lock_guard lock(mutex_);
  if (engine_) return Refusal{409, "sweep_running", "sweep " + std::to_string(sweep_id_) + " drives the bench; abort it first"};
  if (enabled_ || stop_.active()) return Refusal{409, "bench_enabled", "the drives are enabled; disable them before switching the estimator or PWM"};
  mode_ = mode;
  event_locked("mode", "estimator " + std::string(drivers::name(mode.estimator)) + ", pwm " + std::string(drivers::name(mode.pwm)));
  return std::nullopt;
}

void BenchRuntime::estop() {
  std::lock_guard lock(mutex_);
  supervisor_->estop(backend_->clock().now_s(), "E-stop (REST)");
  enabled_ = false;
  stop_.cancel();
}

std::optional<Refusal> BenchRuntime::reset() {
  std::lock_guard lock(mutex_);
  if (auto ec = supervisor_->reset())
    return Refusal{409, "stop_in_progress", "reset refused: " + ec.message()};
  return std::nullopt;
}

BenchStatus BenchRuntime::status() const {
  std::lock_guard lock(mutex_);
  BenchStatus s;
  s.t_s = backend_->clock().now_s();
  s.enabled = enabled_;
  s.stopping = stop_.active();
  s.setpoints = setpoints_;
  s.mode = mode_;
  s.synrm = supervisor_->synrm();
  s.load = supervisor_->load();
  s.phase = supervisor_->phase();
  s.trip = supervisor_->trip();
  s.ticks = ticks_;
  s.overruns = overruns_;
  s.events = events_;
  if (engine_) {
    const auto p = engine_->progress();
    s.sweep = SweepRun{sweep_id_, std::string(bench::name(engine_->state())), p.done, p.total, engine_->error()};
  } else {
    s.sweep = last_sweep_;
  }
  return s;
}

void BenchRuntime::shutdown(std::chrono::milliseconds timeout) {
  {
    std::lock_guard lock(mutex_);
    if (shut_down_) return;
    shut_down_ = true;
  }
  if (thread_.joinable()) {
    {
      // A running sweep is aborted: its ordered stop, and its state recorded.
      std::lock_guard lock(mutex_);
      if (engine_) engine_->abort();
    }
    enable(false);
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      {
        std::lock_guard lock(mutex_);
        const auto ph = supervisor_->phase();
        const bool supervisor_done = ph == bench::SafetyPhase::normal || ph == bench::SafetyPhase::stopped ||
                                     ph == bench::SafetyPhase::estopped;
        if (!engine_ && !stop_.active() && supervisor_done) break;
      }
      std::this_thread::sleep_for(kTick);
    }
    {
      std::lock_guard lock(mutex_);
      quit_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }
  // Whatever happened above, the drives end disabled.
  std::lock_guard lock(mutex_);
  if (engine_) finish_sweep_locked();
  auto dev = backend_->devices();
  dev.load->enable(false);
  dev.synrm->enable(false);
}

}  // namespace synbench::http
