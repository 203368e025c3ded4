// The uncertainty budget of one operating point by the GUM (JCGM 100:2008), k = 1: every
// component with its type, source, standard uncertainty, sensitivity coefficients and
// contributions to P_dcM, P_dcG, P_m, the efficiency and I_m, combined by the law of
// propagation for uncorrelated inputs (GUM 5.1.2), in full and in its point-to-point part
// ("repeat": type A and the quantisations; docs/uncertainty.md). Pure: no devices, no clock.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "drivers/devices.hpp"
#include "drivers/json.hpp"
#include "drivers/uncertainty_config.hpp"

namespace synbench::bench {

// Type A of a window's mean from its B batch means (GUM 4.2.3 with the batch means as the
// independent observations): s(batch means) / sqrt(B); empty for B < 2.
std::optional<double> type_a_of_mean(std::span<const double> batch_means);

// The currents of a VFC gate's equal sub-gates: I_b = (N_b / (T_g / B) - f0) / Kf.
std::vector<double> batch_currents_A(std::span<const std::uint64_t> batch_counts, double gate_s, double f0_Hz,
                                     double kf_Hz_per_A);

// The outputs a budget propagates to, in this order.
enum class Output : std::size_t { pdcm_W, pdcg_W, pm_W, efficiency, im_A };
constexpr std::size_t kOutputs = 5;
constexpr std::array<const char*, kOutputs> kOutputNames{"pdcm_W", "pdcg_W", "pm_W", "efficiency", "im_A"};

struct BudgetComponent {
  std::string name;    // e.g. "I_dcM type A"
  char type = 'B';     // 'A' or 'B'
  std::string source;  // "physics.md Sec. 4", "[assumed] ..."
  std::string unit;    // of u
  std::optional<double> u;  // standard uncertainty; empty: unavailable (see `why`)
  std::string why;          // why u is unavailable
  bool repeat = false;      // independent from point to point (type A, quantisation)
  std::array<double, kOutputs> sensitivity{};  // d output / d input; 0: does not enter
};

struct PointBudget {
  std::vector<BudgetComponent> components;
  // Combined standard uncertainty of each output (every component) and its repeat part; empty
  // when a component it needs is unavailable.
  std::array<std::optional<double>, kOutputs> combined{}, repeat{};
  std::vector<std::string> notes;  // what was assumed, what is unavailable and why

  std::optional<double> u(Output o) const { return combined[static_cast<std::size_t>(o)]; }
  std::optional<double> u_repeat(Output o) const { return repeat[static_cast<std::size_t>(o)]; }
};

// The measured values the budget is evaluated at (the record's), and the windows' batches.
struct BudgetInputs {
  double udc_V = 0, idcm_A = 0, idcg_A = 0;
  double torque_Nm = 0, speed_rpm = 0, im_A = 0;
  double pdcm_W = 0, pdcg_W = 0, pm_W = 0;
  double load_b1_Nms_per_rad = 0;
  double window_s = 0;  // the drives' window (the encoder's quantisation)
  bool power_meter = false;  // the powers are a power meter's own, not U_dc x I_dc
  const drivers::SynrmWindow* synrm = nullptr;
  const drivers::LoadWindow* load = nullptr;
  const drivers::MeterReading* meter = nullptr;
};

PointBudget point_budget(const BudgetInputs& in, const drivers::UncertaintyConfig& cfg);

// The budget as JSON: {"components": [...], "combined": {...}, "repeat": {...}, "notes": [...]}.
synbench::Json to_json(const PointBudget& b);
// The budget as a GUM table: one row per component, then the combined values.
std::string to_text(const PointBudget& b);

}  // namespace synbench::bench
