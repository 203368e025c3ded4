// The supervised point; see supervised_point.hpp.
#include "app/supervised_point.hpp"

#include "bench/load_ramp.hpp"
#include "bench/ordered_stop.hpp"

namespace synbench::app {
namespace {

// One period: wait, let the backend do its link work, read and check the drives.
double step(BenchBackend& backend, bench::SafetySupervisor& supervisor, double next_s) {
  backend.clock().wait_until(next_s);
  const double now = backend.clock().now_s();
  backend.tick(now);
  supervisor.tick(now);
  return now;
}

bool stopping(const bench::SafetySupervisor& s) {
  return s.phase() == bench::SafetyPhase::stopping_load || s.phase() == bench::SafetyPhase::stopping_speed;
}

}  // namespace

double confirm_stopped(BenchBackend& backend, bench::SafetySupervisor& supervisor, double now_s, double tick_s) {
  double t = now_s;
  supervisor.expect_stopped(t);
  while (supervisor.confirming_stop() && !supervisor.alarm()) t = step(backend, supervisor, t + tick_s);
  return t;
}

SupervisedPoint run_supervised_point(BenchBackend& backend, bench::SafetySupervisor& supervisor,
                                     const bench::PointRequest& request, const bench::PointOptions& options) {
  SupervisedPoint out{bench::PointProcedure(backend.devices(), request, options), {}, {}, false};
  auto& proc = out.procedure;
  double t = backend.clock().now_s();
  supervisor.tick(t);
  while (!proc.finished() && !supervisor.tripped()) {
    proc.tick(t);
    if (proc.finished()) break;
    t = step(backend, supervisor, t + options.tick_s);
  }
  if (supervisor.tripped()) {
    // The supervisor's ordered stop, each step bounded by its own timeouts.
    while (stopping(supervisor)) t = step(backend, supervisor, t + options.tick_s);
    out.trip = supervisor.trip();
  } else if (proc.phase() == bench::PointPhase::failed) {
    // A device call failed mid-point: the drives may still run. The bench's ordered stop, at
    // the bench's load ramp, under the supervisor.
    bench::OrderedStop stop;
    bench::OrderedStopOptions opt;
    opt.load_ramp_Nm_per_s = bench::kBenchLoadRamp_Nm_per_s;
    opt.stopped_speed_rpm = options.stop_speed_rpm;
    opt.speed_timeout_s = options.stop_timeout_s;
    const auto& lt = supervisor.load();
    stop.begin(backend.devices(), opt, t, lt ? lt->torque_Nm : request.load_Nm);
    while (!supervisor.tripped() && !stop.tick(t, supervisor.synrm(), supervisor.load()))
      t = step(backend, supervisor, t + options.tick_s);
    while (stopping(supervisor)) t = step(backend, supervisor, t + options.tick_s);
    out.stopped_after_failure = true;
    if (supervisor.tripped()) out.trip = supervisor.trip();
  }
  confirm_stopped(backend, supervisor, t, options.tick_s);
  out.alarm = supervisor.alarm();
  return out;
}

}  // namespace synbench::app
