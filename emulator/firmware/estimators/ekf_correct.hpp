// The measurement update the two EKFs share (EKF-BASIC, EKF-RS): with P H^T and the innovation
// covariance S = H P H^T + R given,
//   x += K nu,  P -= K S K^T,  K = P H^T S^-1.
// With S = L L^T (Cholesky) and W = P H^T L^-T this is x += W (L^-1 nu), P -= W W^T: a symmetric
// rank-M downdate, applied to the lower triangle and mirrored. P stays symmetric by construction,
// where the full product P - K (P H^T)^T needed a symmetrization against round-off; it costs
// N(N+1)/2 M multiply-adds instead of N^2 M plus the N^2 of the symmetrization (EKF-RS: 84
// against 196). Measured with callgrind over 145000 EKF-RS twin steps: the update and its
// P H^T, S took 157 M instructions against 187 M (docs/benchmarks.md).
#pragma once

#include <cmath>

#include <Eigen/Core>

namespace synbench::emulator::firmware {

template <int N, int M>
void ekf_correct(Eigen::Matrix<double, N, 1>& x, Eigen::Matrix<double, N, N>& p,
                 const Eigen::Matrix<double, N, M>& pht, const Eigen::Matrix<double, M, M>& s,
                 const Eigen::Matrix<double, M, 1>& innovation) {
  // Cholesky and forward substitutions written out for the fixed M <= 3: Eigen's LLT solve took
  // its general blocked triangular solver here and cost more than the product it replaced.
  double l[M][M] = {}, inv_diag[M];
  for (int j = 0; j < M; ++j) {
    double d = s(j, j);
    for (int k = 0; k < j; ++k) d -= l[j][k] * l[j][k];
    l[j][j] = std::sqrt(d);
    inv_diag[j] = 1.0 / l[j][j];
    for (int i = j + 1; i < M; ++i) {
      double v = s(i, j);
      for (int k = 0; k < j; ++k) v -= l[i][k] * l[j][k];
      l[i][j] = v * inv_diag[j];
    }
  }
  // W^T = L^-1 (P H^T)^T, column by column, and L^-1 nu.
  Eigen::Matrix<double, M, N> wt;
  for (int c = 0; c < N; ++c) {
    for (int r = 0; r < M; ++r) {
      double v = pht(c, r);
      for (int k = 0; k < r; ++k) v -= l[r][k] * wt(k, c);
      wt(r, c) = v * inv_diag[r];
    }
  }
  Eigen::Matrix<double, M, 1> nu;
  for (int r = 0; r < M; ++r) {
    double v = innovation(r);
    for (int k = 0; k < r; ++k) v -= l[r][k] * nu(k);
    nu(r) = v * inv_diag[r];
  }
  x.noalias() += wt.transpose() * nu;
  for (int j = 0; j < N; ++j) {
    for (int i = j; i < N; ++i) {
      p(i, j) -= wt.col(i).dot(wt.col(j));
      p(j, i) = p(i, j);
    }
  }
}

}  // namespace synbench::emulator::firmware
