// Small numerical helpers shared by the analysis and the adaptive angle search: the parabola
// through a measured minimum and its neighbours, and a least-squares quadratic over a few points.
#pragma once

#include <cstddef>
#include <optional>
#include <span>

namespace synbench::bench {

// y = c0 + c1 (x - x0) + c2 (x - x0)^2; centred on x0 so the fit stays well conditioned at
// angles around 50 deg.
struct Quadratic {
  double x0 = 0, c0 = 0, c1 = 0, c2 = 0;
  double operator()(double x) const {
    const double t = x - x0;
    return c0 + t * (c1 + t * c2);
  }
  // Only meaningful for c2 > 0.
  double vertex() const { return x0 - c1 / (2 * c2); }
};

// Least-squares quadratic through (x[i], y[i]); exact for three points. Empty when there are
// fewer than three distinct abscissae.
std::optional<Quadratic> fit_quadratic(std::span<const double> x, std::span<const double> y);

// The same fit with the standard error of its vertex: residual variance over n - 3 degrees of
// freedom carried to the vertex by the delta method. Empty (unknown) for three points, or when
// the parabola does not open upward.
struct QuadraticFit {
  Quadratic q;
  std::optional<double> vertex_se;
};
std::optional<QuadraticFit> fit_quadratic_se(std::span<const double> x, std::span<const double> y);

// Weighted least squares (weights 1 / u[i]^2) with the points' standard uncertainties u taken as
// known: vertex_se is then the vertex's standard uncertainty from the fit's covariance
// (Phi^T W Phi)^-1 by the delta method (GUM 5.1.2), also for three points, not scaled by the
// residuals. Empty when a u is not > 0, as fit_quadratic_se otherwise.
std::optional<QuadraticFit> fit_quadratic_weighted(std::span<const double> x, std::span<const double> y,
                                                   std::span<const double> u);

// The minimum of sampled values: the smallest sample, refined by the parabola through it and its
// two neighbours when that parabola opens upward. `x` must be strictly increasing. A smallest
// sample at either end is not refined (the true minimum may lie beyond it) and flagged.
struct RefinedMinimum {
  double x = 0;           // abscissa of the minimum (the sample's, or the parabola's vertex)
  double y = 0;           // the parabola's value there (the sample's when not refined)
  std::size_t index = 0;  // the smallest sample
  bool refined = false;
  bool at_edge = false;
};
RefinedMinimum refine_minimum(std::span<const double> x, std::span<const double> y);

// Value at `at` of the parabola through samples index-1, index, index+1 (clamped into range), so
// another quantity can be read at a refined minimum; linear with two samples, the sample itself
// with one.
double interpolate_at(std::span<const double> x, std::span<const double> y, std::size_t index, double at);

}  // namespace synbench::bench
