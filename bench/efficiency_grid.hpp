// The measured efficiency map of one configuration as a grid: the speeds and loads of its cells
// (ascending, equal within 1e-6), efficiency at [row = load][column = speed], nullopt where not
// measured or with no input power. One grid for the contours and for the report's map and table.
#pragma once

#include <optional>
#include <vector>

#include "bench/analysis.hpp"
#include "bench/efficiency_contours.hpp"

namespace synbench::bench {

MeasuredGrid measured_efficiency_grid(const std::vector<EfficiencyCell>& cells, const Configuration& configuration);
// The same grid carrying another field of the cells (an uncertainty), null where it is empty or
// where the efficiency itself is.
MeasuredGrid measured_efficiency_grid(const std::vector<EfficiencyCell>& cells, const Configuration& configuration,
                                      std::optional<double> EfficiencyCell::*field);

}  // namespace synbench::bench
