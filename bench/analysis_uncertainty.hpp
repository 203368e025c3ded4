// Uncertainty of a curve's optima (docs/analysis.md, "Uncertainty"): the points' standard
// uncertainties propagated to the MTPA and ME angles and to the values read there by Monte Carlo
// (JCGM 101, GUM Supplement 1), because the refinement is nonlinear (which sample is smallest can
// change under noise, and then the parabola through it); and the deltas between two curves of one
// bench from their optima's point-to-point parts.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "bench/analysis.hpp"

namespace synbench::bench {

// The optimum of one curve (minimum of im_A when `by_current`, else of pdcm_W) with the other
// quantities read at its angle through the same three samples. Shared by the analysis and every
// Monte Carlo draw, so both refine alike.
CurveOptimum curve_optimum(std::span<const double> angle_deg, std::span<const double> im_A,
                           std::span<const double> pdcm_W, std::span<const double> pm_W, bool by_current);

// One quantity's standard uncertainties at the curve's angles, split in the part independent from
// point to point (`repeat`: type A and quantisation) and the systematic rest, common to the whole
// curve (sqrt(u^2 - u_repeat^2): calibration, sensor gains). Empty vectors: not known for every
// point.
struct SampleUncertainty {
  std::vector<double> repeat, systematic;
  bool known_repeat() const { return !repeat.empty(); }
  bool known() const { return !repeat.empty() && !systematic.empty(); }
};

// A curve's samples (one per distinct angle, ascending) with their uncertainties.
struct CurveSamples {
  std::vector<double> angle_deg, im_A, pdcm_W, pm_W;
  SampleUncertainty im, pdcm, pm, efficiency;
};

struct MonteCarloOptions {
  std::size_t draws = 400;
  std::uint64_t seed = 20081;
};

// Fills the uncertainties of c.mtpa, c.me and the ME-minus-MTPA difference from `draws` draws of
// every sample from N(value, u_repeat), im, pdcm and pm independently; leaves empty whatever
// needs an uncertainty a sample lacks, and the angles' (and the difference's) where the nominal
// optimum is not refined (at an edge, or fewer than three angles).
void propagate_curve_uncertainty(CurveResult& c, const CurveSamples& s, const MonteCarloOptions& options);

// Standard uncertainties and significance (|delta| > 1.96 u) of x minus reference, from the two
// optima's point-to-point parts in quadrature: two curves of one bench share the systematic
// components, which cancel in the difference. Not valid for curves from two benches.
void add_delta_uncertainty(TrajectoryDelta& d, const CurveOptimum& x, const CurveOptimum& reference);

}  // namespace synbench::bench
