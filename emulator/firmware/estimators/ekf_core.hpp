// What the two EKFs (EKF-BASIC, EKF-RS) share around their models: the state and covariance
// with their reset from the thesis' x0 and P0 diagonals, the reluctance floor, the change of
// axes that keeps Ld > Lq, and the output of angle, speed and inductances. Each filter keeps
// its own process and measurement models; only what is the same logic lives here.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <numbers>
#include <utility>

#include <Eigen/Core>

#include "emulator/firmware/estimators/estimator.hpp"

namespace synbench::emulator::firmware {

// N states, of which kRd, kRq (reluctances R' = 1/L', 1/H), kW (w_e) and kTh (th_e) are at the
// given indices.
template <int N, int kRd, int kRq, int kW, int kTh>
class EkfCore {
 public:
  static constexpr int kN = N;
  using State = Eigen::Matrix<double, N, 1>;
  using Cov = Eigen::Matrix<double, N, N>;

  // To a given state and covariance (tests; a restart from a known state).
  void reset(const State& x, const Cov& p) {
    x_ = x;
    p_ = p;
  }
  const State& state() const { return x_; }
  const Cov& covariance() const { return p_; }

 protected:
  void reset_diagonal(const std::array<double, N>& x0, const std::array<double, N>& p0_diag) {
    State x;
    Cov p = Cov::Zero();
    for (int i = 0; i < N; ++i) {
      x(i) = x0[static_cast<std::size_t>(i)];
      p(i, i) = p0_diag[static_cast<std::size_t>(i)];
    }
    reset(x, p);
  }

  // Keeps L = 1/R' finite; then, when asked to and R'd > R'q, applies the exact symmetry
  // (R'd <-> R'q, th_e + pi/2) to the state and covariance. Returns whether the axes were
  // swapped, so a filter with more axis-bound states (EKF-RS's currents) moves those too.
  bool floor_and_order_reluctances(double min_reluctance_per_H, bool enforce_ld_above_lq) {
    x_(kRd) = std::max(x_(kRd), min_reluctance_per_H);
    x_(kRq) = std::max(x_(kRq), min_reluctance_per_H);
    if (!enforce_ld_above_lq || x_(kRd) <= x_(kRq)) return false;
    std::swap(x_(kRd), x_(kRq));
    x_(kTh) += 0.5 * std::numbers::pi;
    p_.row(kRd).swap(p_.row(kRq));
    p_.col(kRd).swap(p_.col(kRq));
    return true;
  }

  // Angle wrapped to (-pi, pi], speed, Ld = 1/R'd, Lq = 1/R'q.
  EstimatorOutput core_output() const {
    EstimatorOutput out;
    out.theta_e_rad = wrap_pi(x_(kTh));
    out.omega_e_rad_s = x_(kW);
    out.ld_H = 1.0 / x_(kRd);
    out.lq_H = 1.0 / x_(kRq);
    return out;
  }

  State x_;
  Cov p_;
};

}  // namespace synbench::emulator::firmware
