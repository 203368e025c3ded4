// The measured current angle and the tolerance it is judged with.
#include "bench/current_angle.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace synbench::bench {
namespace {

constexpr double kRadPerDeg = 3.14159265358979323846 / 180.0;

TEST(CurrentAngle, IsTheAngleOfTheMeanVectorInTheFirmwaresConvention) {
  for (const double deg : {1.0, 30.0, 45.0, 56.0, 89.0}) {
    const double id = 2.0 * std::cos(deg * kRadPerDeg), iq = 2.0 * std::sin(deg * kRadPerDeg);
    EXPECT_NEAR(current_angle_deg(id, iq).value(), deg, 1e-9);
    // Braking: the firmware keeps i_d and turns i_q; the angle is the one it was commanded.
    EXPECT_NEAR(current_angle_deg(id, -iq).value(), deg, 1e-9);
  }
  EXPECT_NEAR(current_angle_deg(0.0, 1.0).value(), 90.0, 1e-12);
  EXPECT_NEAR(current_angle_deg(-1.0, 1.0).value(), 135.0, 1e-12) << "a negative i_d is no motoring angle";
  EXPECT_FALSE(current_angle_deg(0.0, 0.0)) << "a zero vector has no angle";
}

TEST(CurrentAngle, ToleranceGrowsAsTheCurrentFallsAndStopsAtTheFloor) {
  EXPECT_NEAR(angle_tolerance_deg(2.0).value(), 2.0 + std::atan(0.05 / 2.0) / kRadPerDeg, 1e-12);
  EXPECT_NEAR(angle_tolerance_deg(2.0).value(), 3.43, 0.01);
  EXPECT_NEAR(angle_tolerance_deg(0.2).value(), 16.0, 0.1);
  EXPECT_LT(angle_tolerance_deg(5.0).value(), angle_tolerance_deg(1.0).value());
  EXPECT_FALSE(angle_tolerance_deg(0.19)) << "below the floor: not judged";
  EXPECT_FALSE(angle_tolerance_deg(std::nan(""))) << "NaN is never judged as in tolerance";
}

TEST(CurrentAngle, FlagsADifferenceBeyondTheTolerance) {
  auto at = [](double im, double deg) { return std::pair{im * std::cos(deg * kRadPerDeg), im * std::sin(deg * kRadPerDeg)}; };
  {
    const auto [id, iq] = at(2.0, 56.0);
    EXPECT_FALSE(angle_off(56.0, id, iq));
    EXPECT_FALSE(angle_off(53.0, id, iq)) << "3 deg at 2 A is inside 3.43 deg";
    EXPECT_TRUE(angle_off(52.0, id, iq)) << "4 deg at 2 A is outside";
    EXPECT_TRUE(angle_off(60.0, id, iq));
  }
  {
    const auto [id, iq] = at(0.3, 45.0);  // nearly unloaded: 2 + 9.5 deg
    EXPECT_FALSE(angle_off(56.0, id, iq));
    EXPECT_TRUE(angle_off(60.0, id, iq));
  }
  {
    const auto [id, iq] = at(0.1, 10.0);  // below the floor: never flagged
    EXPECT_FALSE(angle_off(80.0, id, iq));
  }
  const auto [id, iq] = at(2.0, 56.0);
  EXPECT_FALSE(angle_off(56.0, id, -iq)) << "a braking point at its angle";
}

}  // namespace
}  // namespace synbench::bench
