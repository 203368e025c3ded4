// Time still needed by a sweep at this run's pace: the time spent so far over the points this
// run measured, times the points left. Points restored from an interrupted run took no time in
// this one, so they count as done but not in the pace. The clock is the caller's: bench time
// for the engine's estimate, wall time for a person waiting (the CLI, the dashboard).
#pragma once

#include <cstddef>
#include <optional>

namespace synbench::bench {

// Empty until this run has measured a point (no pace yet).
inline std::optional<double> remaining_s(double elapsed_s, std::size_t measured_this_run, std::size_t done,
                                         std::size_t total) {
  if (measured_this_run == 0 || total < done) return std::nullopt;
  return elapsed_s / static_cast<double>(measured_this_run) * static_cast<double>(total - done);
}

}  // namespace synbench::bench
