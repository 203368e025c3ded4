// Analysis of stored points (experiment.md Sec. 3, docs/analysis.md): MTPA and ME angles per
// curve refined between grid points, Delta I_m and Delta P_dcM against a reference
// configuration, estimator error histograms with the thesis bin widths, position error against
// load, and the efficiency map at the ME angle. Pure computation over PointRecords; the JSON
// form is what the REST API serves and the dashboard draws.
#pragma once

#include "drivers/json_fwd.hpp"

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "bench/efficiency_contours.hpp"
#include "bench/point_record.hpp"
#include "bench/sweep_plan_configuration.hpp"

namespace synbench::bench {

struct AnalysisOptions {
  Configuration reference = kReferenceConfiguration;
  // Flagged points are left out of every result by default and listed in `excluded`.
  bool exclude_unstable = true;
  bool exclude_faulted = true;
  bool exclude_voltage_limited = true;
  // Measured on the low-speed fallback: not the configuration's own estimator.
  bool exclude_below_min_speed = true;
  // Run on the encoder after the drive's lock guard took over: not the estimator either.
  bool exclude_lock_lost = true;
  // The drive ran at another current angle than the one the point is filed under (angle_off):
  // its I_m and P_dcM belong to a different place on the curve and would bend the fitted optima.
  bool exclude_angle_off = true;
  // Histogram bin widths of the thesis (Figs. 6.16 to 6.19).
  double pos_err_bin_deg = 0.5;
  double ld_err_bin_pct = 5.0;
  double lq_err_bin_pct = 5.0;
  double rs_err_bin_pct = 20.0;
  // Levels and resolution of the efficiency map's iso-lines (default: "nice" steps).
  ContourOptions contours;
  // Monte Carlo propagation of the points' uncertainties to the optima (JCGM 101): draws per
  // curve (400 puts an SD within about 3.5 % of its limit) and the seed, so results repeat.
  std::size_t uncertainty_draws = 400;
  std::uint64_t uncertainty_seed = 20081;
};

// An optimum of one curve, with both quantities (and the shaft power) read at its angle from the
// parabola through the smallest sample and its neighbours.
struct CurveOptimum {
  double angle_deg = 0;
  double im_A = 0;
  double pdcm_W = 0;
  double pm_W = 0;
  double efficiency = 0;  // pm_W / pdcm_W
  bool refined = false;   // false: the smallest sample itself (at an edge, or < 3 angles)
  bool at_edge = false;   // the smallest sample is the first or last angle measured
  // Standard uncertainties (k = 1) of the values read at the optimum (bench/analysis_uncertainty.hpp):
  // `_u` for the absolute value (the Monte Carlo repeat part combined with the points'
  // systematic part), `_u_repeat` the point-to-point part alone, which a difference between two
  // curves of one bench carries. Empty where a point of the curve has no uncertainty.
  std::optional<double> angle_u_deg;
  std::optional<double> im_u_A, im_u_repeat_A;
  std::optional<double> pdcm_u_W, pdcm_u_repeat_W;
  std::optional<double> pm_u_W;
  std::optional<double> efficiency_u, efficiency_u_repeat;
};

// One (configuration, speed, load) curve over the current angle.
struct CurveResult {
  Configuration configuration;
  double speed_rpm = 0, load_Nm = 0;
  std::size_t points = 0;        // records used
  std::vector<double> angles_deg;  // distinct angles measured (repeats averaged), ascending
  CurveOptimum mtpa;             // minimum of im_A
  CurveOptimum me;               // minimum of pdcm_W
  // ME angle minus MTPA angle, its standard uncertainty from the same Monte Carlo draws, and
  // whether 0 lies outside the central 95 % interval of the drawn differences (empty: unknown).
  double me_minus_mtpa_deg = 0;
  std::optional<double> me_minus_mtpa_u_deg;
  std::optional<bool> me_minus_mtpa_significant;
};

// Configuration minus reference at the same (speed, load), on each optimal trajectory.
// The uncertainties combine the two optima's point-to-point parts in quadrature (one bench: the
// systematic parts cancel); significant: |delta| > 1.96 u (empty when u is unknown).
struct TrajectoryDelta {
  double delta_angle_deg = 0, delta_im_A = 0, delta_pdcm_W = 0;
  std::optional<double> delta_angle_u_deg, delta_im_u_A, delta_pdcm_u_W;
  std::optional<bool> delta_angle_significant, delta_im_significant, delta_pdcm_significant;
};
struct DeltaResult {
  Configuration configuration;
  double speed_rpm = 0, load_Nm = 0;
  TrajectoryDelta mtpa, me;
};

struct HistogramBin {
  double from = 0, to = 0;  // [from, to) in the quantity's unit; edges are multiples of the width
  std::size_t count = 0;
};
struct Histogram {
  Configuration configuration;
  std::string quantity;  // record field: pos_err_mean_deg, ld_err_pct, lq_err_pct, rs_err_pct
  std::string unit;      // deg or %
  double bin_width = 0;
  std::size_t count = 0;  // values binned (records where the field is not null)
  double min = 0, mean = 0, max = 0;
  std::vector<HistogramBin> bins;  // contiguous from the lowest to the highest occupied bin
};

// Position error at one (configuration, speed, load) over the angles measured, as in
// Figs. 6.13 to 6.15: min / mean / max of the points' window-mean errors, plus the extremes seen
// inside the windows.
struct PositionErrorResult {
  Configuration configuration;
  double speed_rpm = 0, load_Nm = 0;
  std::size_t points = 0;
  double min_deg = 0, mean_deg = 0, max_deg = 0;
  double window_min_deg = 0, window_max_deg = 0;
};

// One cell of the efficiency map: at the ME angle of its curve.
struct EfficiencyCell {
  Configuration configuration;
  double speed_rpm = 0, load_Nm = 0;
  double angle_deg = 0, pm_W = 0, pdcm_W = 0, efficiency = 0;
  bool refined = false;
  // Those of the curve's ME optimum (CurveOptimum).
  std::optional<double> pm_u_W, pdcm_u_W, efficiency_u, efficiency_u_repeat;
};

struct ExcludedPoint {
  std::size_t record = 0;  // index in the input
  Configuration configuration;
  double speed_rpm = 0, load_Nm = 0, angle_deg = 0;
  std::vector<std::string> reasons;  // "unstable", "fault: overcurrent", "voltage_limited"
};

struct Analysis {
  AnalysisOptions options;
  std::size_t records = 0;
  std::size_t used = 0;
  std::vector<ExcludedPoint> excluded;
  // Ordered by configuration (enum order), then speed, then load.
  std::vector<CurveResult> curves;
  std::vector<DeltaResult> deltas;           // configurations other than the reference
  std::vector<Histogram> histograms;         // per configuration and quantity with data
  std::vector<PositionErrorResult> position_error;  // configurations with a position error
  std::vector<EfficiencyCell> efficiency;
  std::vector<EfficiencyContours> efficiency_contours;  // the map interpolated, with iso-lines
};

Analysis analyze(const std::vector<PointRecord>& records, const AnalysisOptions& options = {});

// Histogram of `values` with bins [k w, (k + 1) w).
std::vector<HistogramBin> histogram_bins(const std::vector<double>& values, double width);

synbench::Json to_json(const Analysis& a);
// One row per curve: MTPA and ME optima, deltas against the reference, position-error summary.
std::string analysis_curves_csv(const Analysis& a);

}  // namespace synbench::bench
