// Adapters from the twin's firmware objects to the typed device interfaces, and virtual time.
#include "emulator/twin_bench.hpp"

#include <cmath>

#include "drivers/error.hpp"

namespace synbench::emulator {
namespace {

class SynrmAdapter final : public drivers::SynrmDrive {
 public:
  explicit SynrmAdapter(Twin& t) : t_(t) {}
  std::error_code enable(bool on) override { return fw().enable(on); }
  std::error_code set_speed_rpm(double v) override { return fw().set_speed_rpm(v); }
  std::error_code set_angle_deg(double v) override { return fw().set_angle_deg(v); }
  std::error_code set_pwm(drivers::Pwm p) override { return fw().set_pwm(p); }
  std::error_code set_estimator(drivers::Estimator e) override { return fw().set_estimator(e); }
  std::error_code reset_fault() override { return fw().reset_fault(); }
  std::error_code read(drivers::SynrmTelemetry& out) override {
    out = fw().telemetry();
    return {};
  }
  std::error_code read_window(drivers::SynrmWindow& out) override {
    if (t_.window_open()) return make_error_code(errc::not_ready);
    out = fw().window_result();
    return {};
  }

 private:
  firmware::SynrmDriveFirmware& fw() { return t_.synrm_drive(); }
  Twin& t_;
};

class LoadAdapter final : public drivers::LoadDrive {
 public:
  explicit LoadAdapter(Twin& t) : t_(t) {}
  std::error_code enable(bool on) override { return t_.load_drive().enable(on); }
  std::error_code set_torque_Nm(double v) override { return t_.load_drive().set_torque_Nm(v); }
  std::error_code reset_fault() override { return t_.load_drive().reset_fault(); }
  std::error_code read(drivers::LoadTelemetry& out) override {
    out = t_.load_drive().telemetry();
    return {};
  }
  std::error_code read_window(drivers::LoadWindow& out) override {
    if (t_.window_open()) return make_error_code(errc::not_ready);
    out = t_.load_drive().window_result();
    return {};
  }

 private:
  Twin& t_;
};

class MeterAdapter final : public drivers::PowerMeter {
 public:
  explicit MeterAdapter(Twin& t) : t_(t) {}
  std::error_code read(drivers::MeterReading& out) override {
    if (t_.window_open()) return make_error_code(errc::not_ready);
    out = t_.meter_reading();
    return {};
  }

 private:
  Twin& t_;
};

class TriggerAdapter final : public drivers::WindowTrigger, public drivers::TruthProbe {
 public:
  explicit TriggerAdapter(Twin& t) : t_(t) {}
  std::error_code open_window(double window_s) override {
    if (!(window_s > 0) || !std::isfinite(window_s)) return make_error_code(errc::invalid_argument);
    if (t_.window_open()) return make_error_code(errc::busy);
    t_.open_window(window_s);
    return {};
  }
  bool window_closed() override { return !t_.window_open(); }
  std::optional<drivers::TruthWindow> read_truth_window() override { return t_.truth_window(); }

 private:
  Twin& t_;
};

class VirtualClock final : public drivers::Clock {
 public:
  explicit VirtualClock(Twin& t) : t_(t) {}
  double now_s() const override { return t_.time_s(); }
  void wait_until(double t_s) override {
    const double left = (t_s - t_.time_s()) / t_.step_s();
    if (left > 1e-9) t_.run_steps(static_cast<std::int64_t>(std::ceil(left - 1e-9)));
  }

 private:
  Twin& t_;
};

}  // namespace

struct TwinBench::Adapters {
  explicit Adapters(Twin& t) : synrm(t), load(t), meter(t), trigger(t), clock(t) {}
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

}  // namespace synbench::emulator
