// The thesis grid and the IEC 61800-9-2 points as sweep plans.
#include "bench/sweep_presets.hpp"

#include <cstdio>

namespace synbench::bench {
namespace {

using drivers::Estimator;
using drivers::Pwm;

bool is_eemf(Estimator e) {
  return e == Estimator::eemf_const || e == Estimator::eemf_lut || e == Estimator::eemf_rls;
}

std::string pct(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g %%", v);
  return buf;
}

std::string rpm(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g rpm", v);
  return buf;
}

}  // namespace

PlannedConfiguration with_thesis_defaults(Configuration c) {
  PlannedConfiguration p{c, 0, std::nullopt, std::nullopt};
  if (is_eemf(c.estimator)) p.min_speed_rpm = kThesisEemfMinSpeed_rpm;
  if (c.estimator == Estimator::hfi) p.max_speed_rpm = kThesisHfiMaxSpeed_rpm;
  if (c.estimator == Estimator::hfi || c.estimator == Estimator::eemf_rls)
    p.gate_average_s = kThesisInjectionGateAverage_s;
  return p;
}

std::vector<PlannedConfiguration> thesis_configurations() {
  const Configuration list[] = {
      {Estimator::encoder, Pwm::capwm},    {Estimator::encoder, Pwm::aspwm},
      {Estimator::ekf_basic, Pwm::aspwm},  {Estimator::ekf_rs, Pwm::aspwm},
      {Estimator::hfi, Pwm::capwm},        {Estimator::eemf_const, Pwm::capwm},
      {Estimator::eemf_lut, Pwm::capwm},   {Estimator::eemf_rls, Pwm::capwm},
  };
  std::vector<PlannedConfiguration> out;
  for (const auto& c : list) out.push_back(with_thesis_defaults(c));
  return out;
}

SweepPlan thesis_grid_plan() {
  SweepPlan p;
  p.name = std::string(kThesisGridPreset);
  p.preset = std::string(kThesisGridPreset);
  p.speeds_rpm = inclusive_range(kThesisSpeedFrom_rpm, kThesisSpeedTo_rpm, kThesisSpeedStep_rpm);
  p.loads_Nm = inclusive_range(kThesisLoadFrom_Nm, kThesisLoadTo_Nm, kThesisLoadStep_Nm);
  p.angles_deg = inclusive_range(kThesisAngleFrom_deg, kThesisAngleTo_deg, kThesisAngleStep_deg);
  p.configurations = thesis_configurations();
  p.adaptive.from_deg = kThesisAngleFrom_deg;
  p.adaptive.to_deg = kThesisAngleTo_deg;
  p.notes = {
      "Thesis Sec. 6.3.2: 100..900 rpm step 200, 0.5..3.5 N m step 0.5, 40..76 deg step 2 (19 angles; "
      "the thesis also says 23, which that range and step cannot give).",
      "EEMF variants only from 500 rpm, as in the thesis (HFI or the encoder below); HFI, the low-speed "
      "method, only up to 300 rpm."};
  return p;
}

SweepPlan iec_61800_9_2_plan(const IecPresetOptions& o) {
  SweepPlan p;
  p.name = std::string(kIecPreset);
  p.preset = std::string(kIecPreset);
  p.angles_deg = inclusive_range(kThesisAngleFrom_deg, kThesisAngleTo_deg, kThesisAngleStep_deg);
  p.configurations = {PlannedConfiguration{kReferenceConfiguration, 0, std::nullopt, std::nullopt}};
  p.adaptive.from_deg = kThesisAngleFrom_deg;
  p.adaptive.to_deg = kThesisAngleTo_deg;
  bool zero_noted = false;
  for (const auto& ip : kIecPoints) {
    const std::string id = "IEC 61800-9-2 (" + pct(ip.speed_pct) + ", " + pct(ip.torque_pct) + ")";
    const double load = o.rated_torque_Nm * ip.torque_pct / 100.0;
    if (ip.speed_pct == 0) {
      if (!zero_noted) {
        p.notes.push_back(
            o.zero_speed_rpm > 0
                ? "The 0 % speed points are measured at " + rpm(o.zero_speed_rpm) +
                      ": the braking load machine needs a turning shaft, and at standstill there is no "
                      "output power to measure."
                : "The 0 % speed points are left out: the braking load machine needs a turning shaft, "
                  "and at standstill there is no output power to measure.");
        zero_noted = true;
      }
      if (o.zero_speed_rpm <= 0) continue;
      p.operating_points.push_back({o.zero_speed_rpm, load, id + " at " + rpm(o.zero_speed_rpm)});
    } else {
      p.operating_points.push_back({o.rated_speed_rpm * ip.speed_pct / 100.0, load, id});
    }
  }
  p.notes.push_back("Rated " + rpm(o.rated_speed_rpm) + " and " + [&] {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g N m", o.rated_torque_Nm);
    return std::string(buf);
  }() + "; at 90 % speed and full torque the drive may reach the DC-bus voltage limit (the thesis kept "
                                   "high-torque tests at or below 900 rpm): such points are recorded voltage_limited.");
  return p;
}

}  // namespace synbench::bench
