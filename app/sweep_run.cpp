// A sweep into the store; see sweep_run.hpp.
#include "app/sweep_run.hpp"

#include "app/supervised_point.hpp"

namespace synbench::app {

db::EventKind sweep_event_kind(const std::string& kind) {
  return kind == "fault" || kind == "alarm" ? db::EventKind::fault
         : kind == "state"                  ? db::EventKind::state
                                            : db::EventKind::log;
}

class SweepRun::Sink final : public bench::SweepSink {
 public:
  Sink(db::Store& store, std::int64_t id, bench::SweepSink* observer) : store_(store), id_(id), observer_(observer) {}
  std::error_code store_point(std::size_t index, const bench::PointRecord& r) override {
    const auto st = store_.insert_point(id_, static_cast<std::int64_t>(index), r);
    if (!st) {
      // The engine faults the sweep with this message and records the fault event itself.
      last_failure_ = st.error().message;
      return st.code();
    }
    if (observer_) observer_->store_point(index, r);
    return {};
  }
  std::string failure_message(std::error_code ec) const override {
    return last_failure_.empty() ? ec.message() : last_failure_;
  }
  void event(const std::string& kind, const std::string& message) override {
    (void)store_.add_event(id_, sweep_event_kind(kind), message);
    if (observer_) observer_->event(kind, message);
  }
  void progress(const bench::SweepProgress& p) override {
    if (observer_) observer_->progress(p);
  }

 private:
  db::Store& store_;
  std::int64_t id_;
  bench::SweepSink* observer_;
  std::string last_failure_;
};

SweepRun::SweepRun(drivers::BenchDevices devices, bench::SafetySupervisor& supervisor, db::Store& store, std::int64_t id,
                   bench::SweepPlan plan, std::map<std::size_t, bench::PointRecord> stored, SweepRunOptions options)
    : supervisor_(supervisor),
      bench_limits_(supervisor.limits()),
      store_(store),
      id_(id),
      sparse_(plan.mode == bench::SweepMode::adaptive),
      sink_(std::make_unique<Sink>(store, id, options.observer)) {
  // A plan may only tighten what the bench allows, on the daemon as on the command line.
  supervisor_.set_limits(bench::stricter(bench_limits_, bench::safety_limits(plan)));
  engine_ = std::make_unique<bench::SweepEngine>(devices, supervisor_, std::move(plan), std::move(stored), *sink_,
                                                 options.calibration);
}

SweepRun::~SweepRun() { supervisor_.set_limits(bench_limits_); }

std::optional<std::string> SweepRun::begin() {
  if (auto r = store_.set_sweep_state(id_, db::SweepState::running); !r) return r.error().message;
  return std::nullopt;
}

db::SweepState SweepRun::final_state() const {
  switch (engine_->state()) {
    case bench::SweepState::completed: return db::SweepState::completed;
    case bench::SweepState::aborted: return db::SweepState::aborted;
    default: return db::SweepState::faulted;
  }
}

std::optional<std::string> SweepRun::finish() {
  std::optional<std::string> err;
  if (!engine_->error().empty()) err = engine_->error();
  if (auto r = store_.set_sweep_state(id_, final_state(), err, sparse_); !r) return r.error().message;
  return std::nullopt;
}

double run_to_end(BenchBackend& backend, bench::SafetySupervisor& supervisor, bench::SweepEngine& engine, double tick_s,
                  const std::function<bool()>& interrupted, const std::function<void()>& on_abort) {
  double t = backend.clock().now_s();
  bool abort_sent = false;
  while (!engine.finished()) {
    if (!abort_sent && interrupted && interrupted()) {
      engine.abort();
      abort_sent = true;
      if (on_abort) on_abort();
    }
    t += tick_s;
    backend.clock().wait_until(t);
    backend.tick(t);
    supervisor.tick(t);
    engine.tick(t);
  }
  // However the sweep ended, the drives are read back stopped (or the alarm is raised).
  return confirm_stopped(backend, supervisor, t, tick_s);
}

}  // namespace synbench::app
