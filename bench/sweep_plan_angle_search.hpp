// Adaptive current-angle search for one (speed, load, configuration) curve: finds the MTPA angle
// (minimum I_m) and the ME angle (minimum P_dcM) from a handful of measured points instead of the
// full angle grid. A pure state machine: it proposes the next angle, the sweep engine measures
// it and reports both quantities back. It never measures, sleeps or keeps time.
//
// Method (docs/sweep-plan.md, "Adaptive angle search"):
//  1. golden-section search on I_m over the bracket, until the bracket is narrower than 5/3 of
//     the stencil; every point also records P_dcM;
//  2. stencil: points one stencil width below the lower and above the upper of the two current
//     optimum estimates, so each objective has measurements on both sides of its minimum (ME lies
//     some degrees above MTPA on this machine, thesis Sec. 3.1, 6.3.3);
//  3. parabolic finish: a least-squares parabola per objective over the points within 1.5
//     stencil widths of its estimate (twice, re-centred on the vertex; over 2.5 widths when that
//     is better determined); one more point at the vertex (or between both vertices when they are
//     close) if none is within tolerance_deg;
//  4. while the residuals say a vertex is uncertain by more than half the tolerance (noise),
//     more points around the optima, up to max_evaluations;
//     with angle_u_target_deg instead: while either angle's standard uncertainty, from the
//     points' reported u through the weighted fit, is above the target, more points at the
//     optimum's stencil ends and vertex (where it has the fewest), up to max_evaluations.
// Fitting a parabola over a wide stencil averages measurement noise, which comparing nearby
// points (as golden section alone does) cannot: near the minimum I_m changes by only ~0.03 %
// per degree squared.
//
// Deterministic: the proposals depend only on the reported values, so a sweep resumed from the
// database replays its stored points through report() and continues where it stopped.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

namespace synbench::bench {

struct AngleSearchOptions {
  double from_deg = 40.0;            // bracket searched (the thesis grid's angle range)
  double to_deg = 76.0;
  double tolerance_deg = 1.0;        // target accuracy: no new point closer than this to a fitted
                                     // vertex; stencil points at least 2.5 times this apart
  double stencil_deg = 6.0;          // half width of the fitting stencil around each optimum
  std::size_t max_evaluations = 7;   // hard cap per curve
  double resolution_deg = 0.01;      // proposals are rounded to this (the drive register's step)
  // "Measure until sure": keep adding points near the optima until the standard uncertainty of
  // both the MTPA and the ME angle (from the weighted fit, the points' reported u) is at most
  // this, or max_evaluations is reached. None: stop on tolerance_deg as before.
  std::optional<double> angle_u_target_deg;
  bool operator==(const AngleSearchOptions&) const = default;
};

struct AngleSearchEvaluation {
  double angle_deg = 0, im_A = 0, pdcm_W = 0;
  // The point's standard uncertainties, their point-to-point parts (the record's im_u_repeat_A,
  // pdcm_u_repeat_W): what scatters between the points of one curve. Empty: not known.
  std::optional<double> im_u_A, pdcm_u_W;
};

// One optimum with both quantities read there from the fitted parabolas.
struct AngleOptimum {
  double angle_deg = 0;
  double im_A = 0;
  double pdcm_W = 0;
  bool refined = false;          // a parabola opening upward was fitted; else the best point
  bool at_edge = false;          // the minimum is at an end of the bracket (it may lie beyond)
  std::size_t points_used = 0;   // points inside the fitting window
  std::optional<double> angle_se_deg;  // standard error of angle_deg from the fit's residuals;
                                       // unknown with only three points in the window
  // Standard uncertainty of angle_deg from the points' reported u (weighted fit, its covariance
  // by the delta method); known with angle_u_target_deg set and every point in the window
  // reported with its u. The parabola is then the weighted one, and angle_deg its vertex.
  std::optional<double> angle_u_deg;
};

struct AngleSearchResult {
  AngleOptimum mtpa;  // minimum of im_A
  AngleOptimum me;    // minimum of pdcm_W
  std::size_t evaluations = 0;
  // Both angles' angle_u_deg known and at most options' angle_u_target_deg (false without one).
  bool angle_u_target_met = false;
};

class AngleSearch {
 public:
  explicit AngleSearch(AngleSearchOptions options = {});

  // The next angle to measure, or nothing when the search is finished (or the cap is reached).
  std::optional<double> next_angle() const;
  // The measured values at `angle_deg` (normally the angle next_angle() proposed), with their
  // point-to-point standard uncertainties when known (needed for angle_u_target_deg).
  void report(double angle_deg, double im_A, double pdcm_W, std::optional<double> im_u_A = std::nullopt,
              std::optional<double> pdcm_u_W = std::nullopt);

  bool finished() const { return !next_angle(); }
  const std::vector<AngleSearchEvaluation>& evaluations() const { return points_; }
  const AngleSearchOptions& options() const { return opt_; }
  // The current estimates; meaningful once at least one point was reported.
  AngleSearchResult result() const;

 private:
  enum Objective { im = 0, pdcm = 1 };
  double round(double angle_deg) const;
  double clamp(double angle_deg) const;
  double distance_to_points(double angle_deg) const;
  AngleOptimum fit(Objective k) const;
  AngleOptimum fit_in_window(Objective k, double window_deg) const;
  bool target_met(const AngleOptimum& o) const;
  // With angle_u_target_deg: the next point for the optima whose angle u is above the target.
  std::optional<double> toward_target(const AngleOptimum& mtpa, const AngleOptimum& me) const;

  AngleSearchOptions opt_;
  std::vector<AngleSearchEvaluation> points_;
  // Golden-section state on I_m: bracket [ga, gb], interior points x1 < x2 with their values once
  // measured.
  bool golden_ = true;
  double ga_ = 0, gb_ = 0, x1_ = 0, x2_ = 0;
  std::optional<double> f1_, f2_;
};

}  // namespace synbench::bench
