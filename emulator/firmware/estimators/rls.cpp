// RLS stator identification.
#include "emulator/firmware/estimators/rls.hpp"

#include <Eigen/LU>

#include <algorithm>
#include <cmath>

namespace synbench::emulator::firmware {

StatorRls::StatorRls(double forgetting, double p0, double sample_s)
    : lambda_(forgetting), t_(sample_s), p_(Eigen::Matrix<double, 5, 5>::Identity() * p0),
      theta_(Eigen::Matrix<double, 5, 2>::Zero()) {}

void StatorRls::update(double dig, double diq, double ig_mean, double iq_mean, double ug_mean,
                       double uq_mean) {
  Eigen::Matrix<double, 5, 1> phi;
  phi << ig_mean, iq_mean, ug_mean, uq_mean, 1.0;
  const Eigen::RowVector2d y(dig, diq);
  const Eigen::Matrix<double, 5, 1> pphi = p_ * phi;
  const double den = lambda_ + phi.dot(pphi);
  const Eigen::Matrix<double, 5, 1> k = pphi / den;
  theta_ += k * (y - phi.transpose() * theta_);
  p_ = (p_ - k * pphi.transpose()) / lambda_;
  p_ = 0.5 * (p_ + p_.transpose());
}

std::optional<StatorEstimate> StatorRls::estimate() const {
  Eigen::Matrix2d a, b;
  a << theta_(0, 0), theta_(1, 0), theta_(0, 1), theta_(1, 1);
  b << theta_(2, 0), theta_(3, 0), theta_(2, 1), theta_(3, 1);
  if (std::fabs(b.determinant()) < 1e-18) return std::nullopt;
  const Eigen::Matrix2d binv = b.inverse();
  const Eigen::Matrix2d l = t_ * binv;
  const Eigen::Matrix2d ls = 0.5 * (l + l.transpose());
  const double half_diff = 0.5 * (ls(0, 0) - ls(1, 1));
  const double disc = std::sqrt(half_diff * half_diff + ls(0, 1) * ls(0, 1));
  const Eigen::Vector2d offset = -binv * Eigen::Vector2d(theta_(4, 0), theta_(4, 1));
  StatorEstimate e{-0.5 * (binv * a).trace(), 0.5 * ls.trace() + disc, 0.5 * ls.trace() - disc,
                   offset(0), offset(1)};
  if (!(e.lq_H > 0) || !std::isfinite(e.rs_ohm)) return std::nullopt;
  return e;
}

}  // namespace synbench::emulator::firmware
