// The measured efficiency map of one configuration as a grid: the speeds and loads of its cells
// (ascending, equal within 1e-6), efficiency at [row = load][column = speed], nullopt where not
// measured or with no input power. One grid for the contours and for the report's map and table.
#pragma once

#include <vector>

#include "bench/analysis.hpp"
#include "bench/efficiency_contours.hpp"

namespace synbench::bench {

MeasuredGrid measured_efficiency_grid(const std::vector<EfficiencyCell>& cells, const Configuration& configuration);

}  // namespace synbench::bench
