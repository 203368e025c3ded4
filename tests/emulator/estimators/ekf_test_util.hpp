// Helpers shared by the EKF tests: central finite differences, angle wrapping, synthetic rotors.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Core>

namespace synbench::emulator::firmware::test {

inline constexpr double kPi = std::numbers::pi;
inline constexpr double kTs = 1e-4;
// 500 rpm, 2 pole pairs.
inline constexpr double kOmega500 = 2.0 * kPi * 500.0 / 60.0 * 2.0;

// Position error wrapped to (-90, 90] deg: the SynRM's reluctance repeats every 180 deg electrical.
inline double position_error_deg(double estimate_rad, double truth_rad) {
  double e = std::remainder(estimate_rad - truth_rad, kPi);  // [-pi/2, pi/2]
  if (e <= -kPi / 2) e += kPi;
  return e * 180.0 / kPi;
}

// Central-difference Jacobian of fn: R^N -> R^M at x, step h_j = rel_step * max(1, |x_j|).
template <int M, int N, class Fn>
Eigen::Matrix<double, M, N> numeric_jacobian(Fn fn, const Eigen::Matrix<double, N, 1>& x,
                                             double rel_step = 1e-5) {
  Eigen::Matrix<double, M, N> jac;
  for (int j = 0; j < N; ++j) {
    const double step = rel_step * std::max(1.0, std::abs(x(j)));
    Eigen::Matrix<double, N, 1> xp = x, xm = x;
    xp(j) += step;
    xm(j) -= step;
    const Eigen::Matrix<double, M, 1> fp = fn(xp), fm = fn(xm);
    jac.col(j) = (fp - fm) / (xp(j) - xm(j));
  }
  return jac;
}

// Largest element-wise relative error of `numeric` against `analytic`; elements whose analytic
// value is below `floor` in magnitude are compared in absolute terms against `floor`.
template <class A, class B>
double max_relative_error(const A& analytic, const B& numeric, double floor = 1e-9) {
  double worst = 0;
  for (int i = 0; i < analytic.rows(); ++i)
    for (int j = 0; j < analytic.cols(); ++j) {
      const double scale = std::max(std::abs(analytic(i, j)), floor);
      worst = std::max(worst, std::abs(numeric(i, j) - analytic(i, j)) / scale);
    }
  return worst;
}

}  // namespace synbench::emulator::firmware::test
