// Efficiency map as a field with iso-efficiency lines (issue 25): the ME-angle efficiency of each
// configuration interpolated bilinearly inside the measured (speed, load) grid, never outside it
// and never across a cell with a corner not measured, and its iso-lines by marching squares.
// Pure computation over the analysis' efficiency cells; drawn by the dashboard and the report.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "bench/sweep_plan_configuration.hpp"

namespace synbench::bench {

struct EfficiencyCell;

struct ContourOptions {
  // Explicit levels (efficiency as a fraction, e.g. 0.86); empty: every `step` within the data.
  std::vector<double> levels;
  // Distance between levels; 0: a "nice" step (1, 2 or 5 x 10^k) giving about 6 levels.
  double step = 0;
  // Points of the interpolated field per measured interval (>= 1): the field's resolution.
  int subdivisions = 4;
};

using ContourPoint = std::array<double, 2>;                // {speed_rpm, load_Nm}
using ContourSegment = std::array<ContourPoint, 2>;
struct ContourLine {
  double level = 0;
  std::vector<ContourSegment> segments;
};

struct EfficiencyContours {
  Configuration configuration;
  std::vector<double> speed_rpm;  // the field's columns, ascending, from the measured range only
  std::vector<double> load_Nm;    // the field's rows, ascending
  // efficiency[row = load][column = speed]; empty where no measured cell covers the point.
  std::vector<std::vector<std::optional<double>>> efficiency;
  std::vector<double> levels;     // the levels asked for (or chosen) inside the data range
  std::vector<ContourLine> lines;  // one per level that crosses the field, in level order
};

// A measured grid: values[row = load][column = speed], nullopt where not measured.
struct MeasuredGrid {
  std::vector<double> speed_rpm, load_Nm;
  std::vector<std::vector<std::optional<double>>> values;
};

// The levels for data in [lo, hi]: options.levels inside [lo, hi], else multiples of the step
// strictly inside (lo, hi).
std::vector<double> contour_levels(double lo, double hi, const ContourOptions& options);

// The interpolated field and its iso-lines over one measured grid.
EfficiencyContours contours_of(const MeasuredGrid& grid, const ContourOptions& options);

// One entry per configuration in `cells` (cells with pdcm_W <= 0 count as not measured).
std::vector<EfficiencyContours> efficiency_contours(const std::vector<EfficiencyCell>& cells,
                                                    const ContourOptions& options = {});

}  // namespace synbench::bench
