// Parabola refinement and least-squares quadratic fitting.
#include "bench/analysis_fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace synbench::bench {

std::optional<QuadraticFit> fit_quadratic_se(std::span<const double> x, std::span<const double> y) {
  const std::size_t n = std::min(x.size(), y.size());
  if (n < 3) return std::nullopt;
  double mean = 0;
  for (std::size_t i = 0; i < n; ++i) mean += x[i];
  mean /= static_cast<double>(n);
  // Normal equations in t = (x - mean) / spread, so the pivots stay comparable at ~50 deg.
  double spread = 0;
  for (std::size_t i = 0; i < n; ++i) spread = std::max(spread, std::fabs(x[i] - mean));
  if (spread <= 0) return std::nullopt;
  // [A | I | b], Gauss-Jordan: leaves A^-1 (for the vertex's variance) and the coefficients.
  double m[3][7] = {};
  for (std::size_t i = 0; i < n; ++i) {
    const double t = (x[i] - mean) / spread;
    const double phi[3] = {1, t, t * t};
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) m[r][c] += phi[r] * phi[c];
      m[r][6] += phi[r] * y[i];
    }
  }
  for (int r = 0; r < 3; ++r) m[r][3 + r] = 1;
  for (int col = 0; col < 3; ++col) {
    int pivot = col;
    for (int r = col + 1; r < 3; ++r)
      if (std::fabs(m[r][col]) > std::fabs(m[pivot][col])) pivot = r;
    // Fewer than three distinct abscissae make the system singular.
    if (std::fabs(m[pivot][col]) < 1e-12 * static_cast<double>(n)) return std::nullopt;
    for (int c = 0; c < 7; ++c) std::swap(m[col][c], m[pivot][c]);
    const double d = m[col][col];
    for (int c = 0; c < 7; ++c) m[col][c] /= d;
    for (int r = 0; r < 3; ++r) {
      if (r == col) continue;
      const double f = m[r][col];
      for (int c = 0; c < 7; ++c) m[r][c] -= f * m[col][c];
    }
  }
  const double b0 = m[0][6], b1 = m[1][6], b2 = m[2][6];
  QuadraticFit fit;
  fit.q.x0 = mean;
  fit.q.c0 = b0;
  fit.q.c1 = b1 / spread;
  fit.q.c2 = b2 / (spread * spread);
  if (n > 3 && b2 > 0) {
    double rss = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double e = y[i] - fit.q(x[i]);
      rss += e * e;
    }
    const double s2 = rss / static_cast<double>(n - 3);
    // Vertex t* = -b1 / (2 b2); its gradient with respect to (b0, b1, b2).
    const double g[3] = {0, -1 / (2 * b2), b1 / (2 * b2 * b2)};
    double var = 0;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) var += g[r] * m[r][3 + c] * g[c];
    fit.vertex_se = spread * std::sqrt(std::max(0.0, s2 * var));
  }
  return fit;
}

std::optional<Quadratic> fit_quadratic(std::span<const double> x, std::span<const double> y) {
  const auto f = fit_quadratic_se(x, y);
  if (!f) return std::nullopt;
  return f->q;
}

RefinedMinimum refine_minimum(std::span<const double> x, std::span<const double> y) {
  RefinedMinimum m;
  const std::size_t n = std::min(x.size(), y.size());
  if (n == 0) return m;
  for (std::size_t i = 1; i < n; ++i)
    if (y[i] < y[m.index]) m.index = i;
  m.x = x[m.index];
  m.y = y[m.index];
  m.at_edge = n > 1 && (m.index == 0 || m.index == n - 1);
  if (n < 3 || m.at_edge) return m;
  const std::size_t i = m.index;
  const std::array<double, 3> xs{x[i - 1], x[i], x[i + 1]}, ys{y[i - 1], y[i], y[i + 1]};
  const auto q = fit_quadratic(xs, ys);
  if (!q || q->c2 <= 0) return m;
  // The smallest sample is below both neighbours, so the vertex lies between them.
  m.x = std::clamp(q->vertex(), xs[0], xs[2]);
  m.y = (*q)(m.x);
  m.refined = true;
  return m;
}

double interpolate_at(std::span<const double> x, std::span<const double> y, std::size_t index, double at) {
  const std::size_t n = std::min(x.size(), y.size());
  if (n == 0) return 0;
  if (n == 1) return y[0];
  if (n == 2) return y[0] + (y[1] - y[0]) * (at - x[0]) / (x[1] - x[0]);
  const std::size_t i = std::clamp<std::size_t>(index, 1, n - 2);
  // Lagrange form: exact through the three samples whatever their curvature sign.
  const double x0 = x[i - 1], x1 = x[i], x2 = x[i + 1];
  return y[i - 1] * (at - x1) * (at - x2) / ((x0 - x1) * (x0 - x2)) +
         y[i] * (at - x0) * (at - x2) / ((x1 - x0) * (x1 - x2)) +
         y[i + 1] * (at - x0) * (at - x1) / ((x2 - x0) * (x2 - x1));
}

}  // namespace synbench::bench
