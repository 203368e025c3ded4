// One operating point as a state machine ticked with the current time: command the drives,
// spin up, apply the load, wait for steady state, measure one window on every instrument at
// once, record, and end with the ordered stop (load torque to zero, then speed, then disable).
// It never sleeps; run_point() below is the loop that waits on a Clock.
#pragma once

#include <optional>
#include <string>
#include <system_error>

#include "bench/load_ramp.hpp"
#include "bench/ordered_stop.hpp"
#include "bench/point_record.hpp"
#include "bench/steady_state.hpp"
#include "bench/uncertainty.hpp"
#include "drivers/clock.hpp"
#include "drivers/devices.hpp"

namespace synbench::bench {

struct PointRequest {
  double speed_rpm = 0;
  double load_Nm = 0;
  double angle_deg = 45;
  drivers::Estimator estimator = drivers::Estimator::encoder;
  drivers::Pwm pwm = drivers::Pwm::capwm;
  double window_s = 1.0;
};

struct PointOptions {
  double tick_s = 0.01;                 // how often the bench reads telemetry
  double min_settle_s = 0.5;            // after the load is applied, before the gate may pass
  double settle_timeout_s = 30.0;       // then the point is measured anyway and flagged unstable
  double spin_up_timeout_s = 30.0;
  double speed_reached_band_rpm = 5.0;
  double stop_speed_rpm = 20.0;         // below this the drives are disabled
  double stop_timeout_s = 30.0;        // the ordered stop's speed step, then disabled regardless
  // A read that fails on the link (no reply, a garbled reply, an exception: errors the bus
  // already repeated within its retry budget) skips the tick; the point fails only when no
  // telemetry, or no window result, came for this long. The safety supervisor's link deadline.
  double telemetry_timeout_s = 0.5;
  // A window the bench keeps itself (a device without window registers) must last, by its
  // samples, what was asked and what the meter's time base counted, within one poll period and
  // this much: the link deadline a read may fail for before the point fails (telemetry_timeout_s),
  // the most a sample may come late without anything being wrong.
  double host_window_jitter_s = 0.5;
  double load_b1_Nms_per_rad = 2.0e-4;  // load machine friction B1G: P_m = T_L w + B1G w^2 (6.1)
  // The type B inputs of the point's uncertainty budget (bench config "uncertainty").
  drivers::UncertaintyConfig uncertainty;
  bool ordered_stop_after = true;
  // In a sweep the drives stay running between points: when the SynRM drive already runs, the
  // new setpoints are commanded together and the gate decides when the bench has settled.
  bool continue_running = false;
  // The bench moves the load torque setpoint at this rate (0: steps it). A sensorless observer
  // must track the deceleration the load change causes until the 3 Hz speed loop answers: a
  // 2.5 N m step (ramped by the load drive within 0.25 s) stalled EEMF-LUT at 700 rpm, 56 deg
  // (a PI tracking loop lags an acceleration alpha by alpha / wn^2), 2 N m/s did not.
  double load_ramp_Nm_per_s = kBenchLoadRamp_Nm_per_s;
  // A sensorless point started from rest [ours] spins up and takes its load at no more than
  // `sensorless_start_angle_deg`, moving to its own angle once loaded (0: its own from the
  // start), and its load comes from `sensorless_load_at_speed_fraction` of the speed on instead
  // of once the speed is reached. Unloaded, the spin-up's speed overshoot takes the current down
  // to a few hundred mA: an EEMF, proportional to i_d, is then a few volts, and EEMF-CONST
  // slipped at every load at 700 rpm, 58 deg and at 500 rpm, 40 deg, long before the load came.
  // At 45 deg the EEMF is larger and the shaft (below the MTPA angle) steadies the angle error,
  // and loaded the observer holds the move up (docs/estimators.md). Chained points keep theirs.
  double sensorless_start_angle_deg = 45.0;
  double sensorless_load_at_speed_fraction = 0.8;
  // A drive that cannot hold the commanded speed while settling (a sensorless observer that lost
  // the rotor: the shaft stalls while the estimate spins on) is measured at once, flagged
  // unstable and reported by speed_lost(), instead of waiting out the gate's timeout (a sweep
  // then restarts the drives for its next point). Off the speed by more than
  // max(rel x |setpoint|, min) for `speed_lost_s`.
  double speed_lost_band_rel = 0.2;
  double speed_lost_band_min_rpm = 50.0;
  double speed_lost_s = 1.0;
  SteadyStateBands gate;
  // Thermal precondition (Sec. 6.3.2): measure only within target +/- band; a cold machine is
  // warmed with `warmup_load_Nm`, a hot one cooled unloaded; after `timeout_s` the point is
  // measured anyway and flagged unstable.
  struct Thermal {
    double target_C = 50.0, band_C = 5.0, warmup_load_Nm = 3.5, timeout_s = 1800.0;
  };
  std::optional<Thermal> thermal;
};

enum class PointPhase { start, spin_up, load_up, settle, thermal, measure, stop, done, failed };

class PointProcedure {
 public:
  PointProcedure(drivers::BenchDevices devices, PointRequest request, PointOptions options);

  void tick(double now_s);
  PointPhase phase() const { return phase_; }
  bool finished() const { return phase_ == PointPhase::done || phase_ == PointPhase::failed; }
  // Set once the window was measured (also when the point was unstable or limited). Never when a
  // fault latched or a device read failed from the window's open until the record was complete.
  bool has_record() const { return has_record_; }
  const PointRecord& record() const { return record_; }
  // The record's uncertainty budget (bench/uncertainty.hpp); set with the record.
  const std::optional<PointBudget>& budget() const { return budget_; }
  // Why the procedure failed: which device call and what it said.
  const std::string& error() const { return error_; }
  // The drive could not hold the commanded speed while settling (see PointOptions).
  bool speed_lost() const { return speed_lost_; }
  // Failed reads the procedure skipped over (a lossy link), for logs and tests.
  std::uint64_t tolerated_reads() const { return tolerated_reads_; }

 private:
  bool check(std::error_code ec, const char* what);
  // A failed read at `now_s`: true while it is tolerated (the tick is skipped), else the point
  // fails naming `what`. `since_s` is when reads last succeeded.
  bool tolerate(std::error_code ec, const char* what, double now_s, double since_s);
  // A command's result. Every step that commands is idempotent (setpoints, modes, enables), so a
  // write the link lost is made again on the next tick: false (the caller returns) while that is
  // tolerated, since `failing_since_s` (-1: not failing), else the point fails.
  bool command(std::error_code ec, const char* what, double now_s, double& failing_since_s);
  // Opens the window on every instrument at once and measures (phase measure).
  void open_window(double now_s);
  // The load torque the procedure wants; ramp_load() moves the setpoint there each tick.
  void command_load(double target_Nm);
  bool ramp_load(double now_s);
  // `ramped`: the load comes off at the bench's ramp (a measured point), else at once (a fault).
  void begin_stop(double now_s, bool ramped);
  // The window's results into the record; on an error, `what` names the read. An implausible
  // result fails the point (error_ set, errc::ok returned).
  std::error_code read_results(const char*& what);
  void enter(PointPhase p, double now_s);

  drivers::BenchDevices dev_;
  PointRequest req_;
  PointOptions opt_;
  SteadyStateGate gate_;
  PointPhase phase_ = PointPhase::start;
  double t_start_ = 0, t_phase_ = 0, t_window_ = 0, t_thermal_ = -1, t_off_speed_ = -1;
  bool has_record_ = false, speed_lost_ = false;
  LoadRamp load_ramp_;
  double t_last_tick_ = -1;
  double t_last_read_ = -1;     // telemetry last read (or the first tick)
  double t_results_due_ = -1;   // the window closed; results since then
  // The window's close was seen; its results are read on a later tick, after a telemetry read
  // that found no fault (a drive that faulted as the window closed fails the point).
  bool window_closed_ = false;
  double t_step_failing_ = -1;  // a command of the current step failing on the link since
  double t_ramp_failing_ = -1;  // the load ramp's writes failing since
  std::uint64_t tolerated_reads_ = 0;
  std::string detail_;  // the failing device's error_detail(), added to error_ by check()
  bool load_pending_ = false;
  OrderedStop stop_;
  bool stop_ramped_ = false;  // the stop takes the load off at the ramp (a measured point)
  bool sensorless_start_ = false;  // a sensorless estimator, started from rest
  bool early_load_ = false;        // its load commanded before the speed was reached
  bool angle_pending_ = false;     // spun up at the sensorless start angle; its own comes when loaded
  bool lock_seen_ = false;         // the drive's lock guard was seen not tripped during this point
  PointRecord record_;
  std::optional<PointBudget> budget_;
  std::string error_;
};

// Runs the procedure to its end, waiting on `clock` between ticks.
PointProcedure run_point(drivers::BenchDevices devices, drivers::Clock& clock,
                         const PointRequest& request, const PointOptions& options);

}  // namespace synbench::bench
