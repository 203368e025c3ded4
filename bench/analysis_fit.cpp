// Parabola refinement and least-squares quadratic fitting.
#include "bench/analysis_fit.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace synbench::bench {

namespace {

// Both fits: unweighted with the residual variance (u empty), or weighted with known u.
std::optional<QuadraticFit> fit_quadratic_impl(std::span<const double> x, std::span<const double> y,
                                               std::span<const double> u) {
  const bool weighted = !u.empty();
  const auto n = static_cast<Eigen::Index>(std::min(x.size(), y.size()));
  if (n < 3 || (weighted && u.size() < static_cast<std::size_t>(n))) return std::nullopt;
  double mean = 0;
  for (Eigen::Index i = 0; i < n; ++i) mean += x[static_cast<std::size_t>(i)];
  mean /= static_cast<double>(n);
  // In t = (x - mean) / spread the columns stay comparable at angles around 50 deg.
  double spread = 0;
  for (Eigen::Index i = 0; i < n; ++i) spread = std::max(spread, std::fabs(x[static_cast<std::size_t>(i)] - mean));
  if (spread <= 0) return std::nullopt;
  Eigen::MatrixX3d phi(n, 3);
  Eigen::VectorXd rhs(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double t = (x[k] - mean) / spread;
    // Weighted: each row divided by its u, so the ordinary solution is the weighted one.
    const double w = weighted ? 1 / u[k] : 1.0;
    if (!(w > 0) || !std::isfinite(w)) return std::nullopt;
    phi.row(i) << w, w * t, w * t * t;
    rhs(i) = w * y[k];
  }
  // QR of the design matrix, never the normal equations: their condition number is its square.
  const Eigen::ColPivHouseholderQR<Eigen::MatrixX3d> qr(phi);
  if (qr.rank() < 3) return std::nullopt;  // fewer than three distinct abscissae
  const Eigen::Vector3d b = qr.solve(rhs);
  QuadraticFit fit;
  fit.q.x0 = mean;
  fit.q.c0 = b(0);
  fit.q.c1 = b(1) / spread;
  fit.q.c2 = b(2) / (spread * spread);
  if ((weighted || n > 3) && b(2) > 0) {
    const double s2 = weighted ? 1.0 : (phi * b - rhs).squaredNorm() / static_cast<double>(n - 3);
    // (Phi^T Phi)^-1 = P R^-1 R^-T P^T from the pivoted QR.
    const Eigen::Matrix3d r = qr.matrixR().topLeftCorner<3, 3>().triangularView<Eigen::Upper>();
    const Eigen::Matrix3d r_inv = r.triangularView<Eigen::Upper>().solve(Eigen::Matrix3d::Identity());
    const Eigen::Matrix3d p = qr.colsPermutation();
    const Eigen::Matrix3d cov = p * r_inv * r_inv.transpose() * p.transpose();
    // Vertex t* = -b1 / (2 b2); its gradient with respect to (b0, b1, b2) (the delta method).
    const Eigen::Vector3d g(0, -1 / (2 * b(2)), b(1) / (2 * b(2) * b(2)));
    fit.vertex_se = spread * std::sqrt(std::max(0.0, s2 * g.dot(cov * g)));
  }
  return fit;
}

}  // namespace

std::optional<QuadraticFit> fit_quadratic_se(std::span<const double> x, std::span<const double> y) {
  return fit_quadratic_impl(x, y, {});
}

std::optional<QuadraticFit> fit_quadratic_weighted(std::span<const double> x, std::span<const double> y,
                                                   std::span<const double> u) {
  if (u.empty()) return std::nullopt;
  return fit_quadratic_impl(x, y, u);
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
  // The parabola through the three samples in Newton's form (closed form: the Monte Carlo of
  // bench/analysis_uncertainty.hpp refines every curve hundreds of times):
  // p(x) = y0 + f01 (x - x0) + f012 (x - x0)(x - x1).
  const double x0 = x[i - 1], x1 = x[i], x2 = x[i + 1];
  const double f01 = (y[i] - y[i - 1]) / (x1 - x0), f12 = (y[i + 1] - y[i]) / (x2 - x1);
  const double f012 = (f12 - f01) / (x2 - x0);
  if (!(f012 > 0)) return m;
  // The smallest sample is below both neighbours, so the vertex lies between them.
  m.x = std::clamp(0.5 * (x0 + x1) - f01 / (2 * f012), x0, x2);
  m.y = y[i - 1] + (m.x - x0) * (f01 + f012 * (m.x - x1));
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
