// Adapters from the twin's firmware objects to the typed device interfaces, and virtual time.
#include "emulator/twin_bench.hpp"

#include <cmath>

#include "drivers/error.hpp"

namespace synbench::emulator {
namespace {

// Link state shared by the adapters and the clock.
struct Link {
  bool down = false;
  double down_since_s = 0;
  bool watchdog_fired = false;
  std::error_code check() const {
    return down ? make_error_code(errc::disconnected) : std::error_code{};
  }
};

// `if (auto ec = link_.check()) return ec;` first in every call: a cut link answers nothing.
#define SYNBENCH_LINK_OR_RETURN \
  if (auto ec = link_.check()) return ec

class SynrmAdapter final : public drivers::SynrmDrive {
 public:
  SynrmAdapter(Twin& t, const Link& link) : t_(t), link_(link) {}
  std::error_code enable(bool on) override { SYNBENCH_LINK_OR_RETURN; return fw().enable(on); }
  std::error_code set_speed_rpm(double v) override { SYNBENCH_LINK_OR_RETURN; return fw().set_speed_rpm(v); }
  std::error_code set_angle_deg(double v) override { SYNBENCH_LINK_OR_RETURN; return fw().set_angle_deg(v); }
  std::error_code set_pwm(drivers::Pwm p) override { SYNBENCH_LINK_OR_RETURN; return fw().set_pwm(p); }
  std::error_code set_estimator(drivers::Estimator e) override { SYNBENCH_LINK_OR_RETURN; return fw().set_estimator(e); }
  std::error_code reset_fault() override { SYNBENCH_LINK_OR_RETURN; return fw().reset_fault(); }
  std::error_code read(drivers::SynrmTelemetry& out) override {
    SYNBENCH_LINK_OR_RETURN;
    out = fw().telemetry();
    return {};
  }
  std::error_code read_window(drivers::SynrmWindow& out) override {
    SYNBENCH_LINK_OR_RETURN;
    if (t_.window_open()) return make_error_code(errc::not_ready);
    out = fw().window_result();
    return {};
  }
  double stop_time_s() const override { return t_.synrm_drive().stop_time_s(); }

 private:
  firmware::SynrmDriveFirmware& fw() { return t_.synrm_drive(); }
  Twin& t_;
  const Link& link_;
};

class LoadAdapter final : public drivers::LoadDrive {
 public:
  LoadAdapter(Twin& t, const Link& link) : t_(t), link_(link) {}
  std::error_code enable(bool on) override { SYNBENCH_LINK_OR_RETURN; return t_.load_drive().enable(on); }
  std::error_code set_torque_Nm(double v) override { SYNBENCH_LINK_OR_RETURN; return t_.load_drive().set_torque_Nm(v); }
  std::error_code reset_fault() override { SYNBENCH_LINK_OR_RETURN; return t_.load_drive().reset_fault(); }
  std::error_code read(drivers::LoadTelemetry& out) override {
    SYNBENCH_LINK_OR_RETURN;
    out = t_.load_drive().telemetry();
    return {};
  }
  std::error_code read_window(drivers::LoadWindow& out) override {
    SYNBENCH_LINK_OR_RETURN;
    if (t_.window_open()) return make_error_code(errc::not_ready);
    out = t_.load_drive().window_result();
    return {};
  }

 private:
  Twin& t_;
  const Link& link_;
};

class MeterAdapter final : public drivers::PowerMeter {
 public:
  MeterAdapter(Twin& t, const Link& link) : t_(t), link_(link) {}
  std::error_code read(drivers::MeterReading& out) override {
    SYNBENCH_LINK_OR_RETURN;
    if (t_.window_open()) return make_error_code(errc::not_ready);
    out = t_.meter_reading();
    return {};
  }

 private:
  Twin& t_;
  const Link& link_;
};

class TriggerAdapter final : public drivers::WindowTrigger, public drivers::TruthProbe {
 public:
  TriggerAdapter(Twin& t, const Link& link) : t_(t), link_(link) {}
  std::error_code open_window(double window_s) override {
    SYNBENCH_LINK_OR_RETURN;
    if (!(window_s > 0) || !std::isfinite(window_s)) return make_error_code(errc::invalid_argument);
    if (t_.window_open()) return make_error_code(errc::busy);
    t_.open_window(window_s);
    return {};
  }
  bool window_closed() override { return !t_.window_open(); }
  std::optional<drivers::TruthWindow> read_truth_window() override { return t_.truth_window(); }

 private:
  Twin& t_;
  const Link& link_;
};

class VirtualClock final : public drivers::Clock {
 public:
  VirtualClock(Twin& t, Link& link) : t_(t), link_(link) {}
  double now_s() const override { return t_.time_s(); }
  void wait_until(double t_s) override {
    const double left = (t_s - t_.time_s()) / t_.step_s();
    if (left <= 1e-9) return;
    auto steps = static_cast<std::int64_t>(std::ceil(left - 1e-9));
    if (link_.down && !link_.watchdog_fired) {
      // Run up to the watchdog's expiry, let both drives stop on their own, run the rest.
      const double expiry = link_.down_since_s + TwinBench::kWatchdogTimeout_s;
      const auto before = static_cast<std::int64_t>(std::ceil((expiry - t_.time_s()) / t_.step_s()));
      if (before < steps) {
        t_.run_steps(std::max<std::int64_t>(0, before));
        steps -= std::max<std::int64_t>(0, before);
        t_.load_drive().stop_and_latch(drivers::Fault::watchdog);
        t_.synrm_drive().stop_and_latch(drivers::Fault::watchdog);
        link_.watchdog_fired = true;
      }
    }
    t_.run_steps(steps);
  }

 private:
  Twin& t_;
  Link& link_;
};

#undef SYNBENCH_LINK_OR_RETURN

}  // namespace

struct TwinBench::Adapters {
  explicit Adapters(Twin& t)
      : synrm(t, link), load(t, link), meter(t, link), trigger(t, link), clock(t, link) {}
  Link link;
  SynrmAdapter synrm;
  LoadAdapter load;
  MeterAdapter meter;
  TriggerAdapter trigger;
  VirtualClock clock;
};

TwinBench::TwinBench(const TwinConfig& config)
    : twin_(config), adapters_(std::make_unique<Adapters>(twin_)) {}

TwinBench::~TwinBench() = default;

drivers::BenchDevices TwinBench::devices() {
  return {&adapters_->synrm, &adapters_->load, &adapters_->meter, &adapters_->trigger,
          &adapters_->trigger};
}

drivers::Clock& TwinBench::clock() { return adapters_->clock; }

void TwinBench::set_link_down(bool down) {
  auto& l = adapters_->link;
  if (down && !l.down) {
    l.down_since_s = twin_.time_s();
    l.watchdog_fired = false;
  }
  l.down = down;
}

bool TwinBench::link_down() const { return adapters_->link.down; }

}  // namespace synbench::emulator
