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

// The plain standard error of B batch means, s(batch means) / sqrt(B) (GUM 4.2.3 with the
// batch means as independent observations); empty for B < 2.
std::optional<double> batch_standard_error(std::span<const double> batch_means);

// Type A of a window's mean from its B batch means, allowing for a lag-1 correlation between
// consecutive batches (docs/uncertainty.md, "Type A"): the batch means taken as an MA(1) series
// (white noise plus the difference of a bounded stored energy, (E_k - E_{k-1}) / tau), whose
// mean has the variance (gamma0 + 2 gamma1) / B - 2 gamma1 / B^2. gamma0 and gamma1 are the
// unbiased estimates under that model (the mean-centred lag-0 and lag-1 sums' expectations
// solved for them), gamma1 clamped to [-gamma0 / 2, gamma0 / 2]; a positive gamma1 (positively
// correlated batches) never gives less than s / sqrt(B). B = 2 or 3: s / sqrt(B) (too few
// batches for a lag-1 estimate); B < 2: empty.
struct BatchTypeA {
  double u = 0;                // the type A of the window's mean
  double standard_error = 0;   // s / sqrt(B), for comparison
  double lag1_correlation = 0; // gamma1 / gamma0 after the clamp; 0 when not estimated
  bool lag1 = false;           // the lag-1 model was applied (B >= 4)
};
std::optional<BatchTypeA> batch_type_a(std::span<const double> batch_means);
// The alternative with the same model (docs/uncertainty.md, "Type A"): the window's batches
// regrouped into G = every divisor of B from B down to 2 consecutive groups, V(G) = s_G^2 / G
// fitted by least squares to a + b G, u^2 = a + b (G = 1, the window's mean); a < 0 refitted
// through the origin (u^2 = b). b < 0 (V falling with longer batches: positively correlated
// batches) extrapolates upward. Fewer than two such G (B prime, B < 4): s / sqrt(B).
std::optional<double> regrouped_type_a(std::span<const double> batch_means);
// The type A of a window's mean speed measured from encoder counts (the window's speed is
// Delta-counts / T, each batch's the counts over its batch), under a speed loop with integral
// action: the shaft's position error e against the reference is then bounded, each batch speed
// is omega_ref + (e_k - e_(k-1)) / tau, and the window's mean errs by (e_B - e_0) / T only. The
// running sum of the batch speeds' deviations from their mean is the bridge
// S_k = e_k - e_0 - (k / B)(e_B - e_0); with e independent between batch ends (batches longer
// than the loop's time constant), E[S_k^2] = var(e) (1 + (1 - k/B)^2 + (k/B)^2), so
// var(e) = mean over k = 1..B-1 of S_k^2 / (1 + (2B - 1) / (3B)) and u = sqrt(2 var(e)) / T
// (docs/uncertainty.md, "The speed"). In rpm, with S_k in rpm x tau: no time needed. Fewer than
// 3 batches: unavailable.
std::optional<double> position_bridge_type_a(std::span<const double> batch_speeds_rpm);
// batch_type_a(...).u: the estimator every other type A component of the budget uses.
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
