// The measured current angle and its agreement with the request.
#include "bench/current_angle.hpp"

#include <cmath>

namespace synbench::bench {
namespace {

constexpr double kDegPerRad = 180.0 / 3.14159265358979323846;

}  // namespace

std::optional<double> current_angle_deg(double id_A, double iq_A) {
  if (id_A == 0 && iq_A == 0) return std::nullopt;
  return std::atan2(std::fabs(iq_A), id_A) * kDegPerRad;
}

std::optional<double> angle_tolerance_deg(double im_A) {
  if (!(im_A >= kAngleJudgedFrom_A)) return std::nullopt;
  return kAngleTolerance_deg + std::atan(kCurrentError_A / im_A) * kDegPerRad;
}

bool angle_off(double request_deg, double id_A, double iq_A) {
  const auto tolerance = angle_tolerance_deg(std::hypot(id_A, iq_A));
  const auto measured = current_angle_deg(id_A, iq_A);
  return tolerance && measured && std::fabs(*measured - request_deg) > *tolerance;
}

}  // namespace synbench::bench
