// Recursive least squares identification of the stator in the estimated frame (thesis 2.30 to
// 2.39), two outputs sharing one regressor and one covariance, exponential forgetting.
// The model is the integral of the continuous voltage equation over one sample interval T:
//   i(k) - i(k-1) = A i_mean + B u_mean + c,  A = T F, B = T G,  di/dt = F i + G u + const,
// exact for a linear machine whatever w T is, with the interval means taken from the samples
// inside the interval so that their noise is independent of the end samples'. With
// L = G^-1 (incremental inductances, symmetric) and F = -G (Rs I + w J L):
//   Rs = -tr(B^-1 A) / 2,  L'd, Lq = eigenvalues of sym(T B^-1).
// The constant c takes the affine part of a saturated machine (the back-EMF of flux offsets).
// The thesis' discrete form i(k) - i(k-1) = A i(k-1) + B u(k-1) with Rs = -tr A / tr B is biased
// here by closed-loop data and by the frame's rotation over a 1 ms sample.
// Also the 5-bit PRBS that excites it.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <optional>

namespace synbench::emulator::firmware {

struct StatorEstimate {
  double rs_ohm = 0, ld_H = 0, lq_H = 0;
  // The affine part as a voltage, -B^-1 c = w J psi_off: the back-EMF of the flux offsets of a
  // saturated machine linearised at the operating point (psi = L' i + psi_off).
  double offset_g_V = 0, offset_d_V = 0;
};

class StatorRls {
 public:
  StatorRls(double forgetting, double p0, double sample_s);
  // One interval: the change of the end samples, the mean current and voltage inside.
  void update(double dig, double diq, double ig_mean, double iq_mean, double ug_mean, double uq_mean);
  std::optional<StatorEstimate> estimate() const;

 private:
  double lambda_, t_;
  Eigen::Matrix<double, 5, 5> p_;
  Eigen::Matrix<double, 5, 2> theta_;  // column j: [a_j1 a_j2 b_j1 b_j2 c_j] of output j
};

// 5-bit maximal-length sequence (x^5 + x^3 + 1), +/-1, one bit per `bit_s`.
class Prbs5 {
 public:
  explicit Prbs5(std::uint8_t seed) : state_(static_cast<std::uint8_t>(seed & 31u ? seed & 31u : 1u)) {}
  // Advances by dt and returns the current bit as +1 or -1.
  double advance(double dt_s, double bit_s) {
    elapsed_ += dt_s;
    while (elapsed_ >= bit_s) {
      elapsed_ -= bit_s;
      const std::uint8_t fb = static_cast<std::uint8_t>(((state_ >> 4) ^ (state_ >> 2)) & 1u);
      state_ = static_cast<std::uint8_t>(((state_ << 1) | fb) & 31u);
    }
    return (state_ & 1u) ? 1.0 : -1.0;
  }

 private:
  std::uint8_t state_;
  double elapsed_ = 0;
};

}  // namespace synbench::emulator::firmware
