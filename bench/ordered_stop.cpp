// The ordered stop's three steps.
#include "bench/ordered_stop.hpp"

#include <cmath>

namespace synbench::bench {

void OrderedStop::begin(const drivers::BenchDevices& dev, const OrderedStopOptions& opt,
                        double now_s, double from_Nm) {
  dev_ = dev;
  opt_ = opt;
  step_ = StopStep::load;
  timed_out_ = false;
  hold_speed_rpm_.reset();
  began_s_ = step_since_s_ = last_tick_s_ = now_s;
  ramp_ = LoadRamp(opt.load_ramp_Nm_per_s);
  ramp_.start(from_Nm, 0.0);
  const double ramp_s = opt.load_ramp_Nm_per_s > 0 ? std::fabs(from_Nm) / opt.load_ramp_Nm_per_s : 0.0;
  load_deadline_s_ = now_s + ramp_s + opt.load_timeout_s;
  dev_.load->set_torque_Nm(ramp_.step(0.0));
}

bool OrderedStop::tick(double now_s, const std::optional<drivers::SynrmTelemetry>& synrm,
                       const std::optional<drivers::LoadTelemetry>& load) {
  const double dt = now_s - last_tick_s_;
  last_tick_s_ = now_s;
  switch (step_) {
    case StopStep::load: {
      // Commanded every tick: one write lost on a link must not leave the torque on.
      dev_.load->set_torque_Nm(ramp_.step(dt));
      // While the load comes off, the SynRM holds the speed the shaft has, never more: a
      // voltage-limited drive short of its setpoint (1158 of 1500 rpm) would otherwise
      // accelerate towards it as the load goes, and overshoot the overspeed limit.
      if (!hold_speed_rpm_ && synrm && drivers::running(synrm->state)) {
        hold_speed_rpm_ = synrm->speed_rpm;
        dev_.synrm->set_speed_rpm(*hold_speed_rpm_);
      }
      const bool gone = ramp_.done() && load && std::fabs(load->torque_Nm) < opt_.load_gone_Nm;
      if (gone && opt_.coast) {
        disable_both();
        return true;
      }
      if (!gone && now_s <= load_deadline_s_) return false;
      if (!gone) {
        dev_.load->enable(false);
        timed_out_ = true;
      }
      dev_.synrm->set_speed_rpm(0.0);
      step_ = StopStep::speed;
      step_since_s_ = now_s;
      return false;
    }
    case StopStep::speed: {
      dev_.synrm->set_speed_rpm(0.0);
      const bool still = synrm && std::fabs(synrm->speed_rpm) < opt_.stopped_speed_rpm;
      const bool off = synrm && !drivers::running(synrm->state);
      if (!still && !off) {
        if (now_s - step_since_s_ <= opt_.speed_timeout_s) return false;
        timed_out_ = true;
      }
      disable_both();
      return true;
    }
    case StopStep::idle:
    case StopStep::done:
      return false;
  }
  return false;
}

void OrderedStop::disable_both() {
  dev_.synrm->enable(false);
  dev_.load->enable(false);
  step_ = StopStep::done;
}

}  // namespace synbench::bench
