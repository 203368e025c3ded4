// The drive's lock guard around a scripted estimator: when it takes the angle from the estimator
// (once armed, beyond the guard angle, modulo a half turn, or the guard speed for the guard
// time; before, off the guard speed for 0.2 s; or on a current surge), what it reports
// meanwhile, and the fresh estimator a re-arm starts.
#include "emulator/firmware/estimators/lock_guard.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

namespace synbench::emulator::firmware {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

// Reports the encoder's angle plus a scripted offset, injects 7 V, remembers its alignment.
struct Scripted final : Estimator {
  double offset_rad = 0, theta = 0, aligned_to = NAN, omega = 100.0;
  int updates = 0;
  void update(const EstimatorInput& in) override {
    ++updates;
    theta = in.encoder_theta_e_rad + offset_rad;
  }
  EstimatorOutput output() const override {
    EstimatorOutput o;
    o.theta_e_rad = theta;
    o.omega_e_rad_s = omega;
    o.rs_ohm = 5.0;
    return o;
  }
  void injection(double& ud_V, double& uq_V) const override { ud_V = uq_V = 7.0; }
  void align(double theta_e_rad, double) override { aligned_to = theta_e_rad; }
};

// A guard with the thesis-like settings (45 deg, 50 rad/s, 2 ms, 5 A) that records the
// estimators it makes.
LockGuard make_guard(std::vector<Scripted*>& made) {
  return LockGuard{[&made] {
                     auto e = std::make_unique<Scripted>();
                     made.push_back(e.get());
                     return e;
                   },
                   45 * kDeg, 50.0, 0.002, 5.0, 1e-4};
}

struct Fixture {
  std::vector<Scripted*> made;
  LockGuard guard = make_guard(made);
  EstimatorInput in;
  Fixture() {
    in.encoder_omega_e_rad_s = 90.0;
    steps(500, 0.0);  // 50 ms within the guard angle: armed
  }
  void steps(int n, double offset_deg) {
    made.back()->offset_rad = offset_deg * kDeg;
    for (int k = 0; k < n; ++k) {
      in.encoder_theta_e_rad = std::remainder(in.encoder_theta_e_rad + 0.01, 2 * kPi);
      guard.update(in);
    }
  }
};

TEST(LockGuard, HoldsOffWithinTheGuardAngleAndForAHalfTurn) {
  Fixture f;
  f.steps(5000, 44.0);
  f.steps(5000, 180.0 + 30.0);  // the SynRM's other, equally valid, lock
  f.steps(19, 60.0);            // beyond, but 1.9 ms < 2 ms
  f.steps(100, 0.0);
  EXPECT_FALSE(f.guard.lock_lost());
  EXPECT_EQ(f.made.size(), 1u);
  EXPECT_NEAR(f.guard.output().theta_e_rad, f.in.encoder_theta_e_rad, 1e-12);
  double ud = 0, uq = 0;
  f.guard.injection(ud, uq);
  EXPECT_EQ(ud, 7.0);
}

TEST(LockGuard, TakesTheEncoderAfterTheGuardTimeUntilRearmedWithAFreshEstimator) {
  Fixture f;
  f.steps(19, -50.0);
  EXPECT_FALSE(f.guard.lock_lost());
  f.steps(1, -50.0);
  ASSERT_TRUE(f.guard.lock_lost()) << "20 periods of 0.1 ms beyond 45 deg";
  const int fed = f.made.back()->updates;
  f.steps(300, -50.0);
  EXPECT_TRUE(f.guard.lock_lost()) << "latched: it does not hand back by itself";
  EXPECT_EQ(f.made.back()->updates, fed) << "the lost estimator is not fed";
  const EstimatorOutput o = f.guard.output();
  EXPECT_EQ(o.theta_e_rad, f.in.encoder_theta_e_rad);
  EXPECT_EQ(o.omega_e_rad_s, 90.0);
  double ud = 1, uq = 1;
  f.guard.injection(ud, uq);
  EXPECT_EQ(ud, 0.0);
  EXPECT_EQ(uq, 0.0);

  f.guard.rearm();
  EXPECT_FALSE(f.guard.lock_lost());
  ASSERT_EQ(f.made.size(), 2u);
  EXPECT_EQ(f.made.back()->aligned_to, f.in.encoder_theta_e_rad) << "handed the encoder's angle";
  f.guard.rearm();
  EXPECT_EQ(f.made.size(), 2u) << "a re-arm without a trip keeps the estimator";
}

TEST(LockGuard, ArmsOnlyOnceTheEstimatorHasFoundTheRotor) {
  // An estimator converging from its initial state crosses the guard angle on its way in.
  std::vector<Scripted*> made;
  LockGuard guard = make_guard(made);
  EstimatorInput in;
  in.encoder_omega_e_rad_s = 100.0;  // the scripted speed: only the angle is off
  made.back()->offset_rad = 80 * kDeg;
  for (int k = 0; k < 1000; ++k) guard.update(in);
  EXPECT_FALSE(guard.lock_lost()) << "not armed yet";
  made.back()->offset_rad = 0;
  for (int k = 0; k < 499; ++k) guard.update(in);
  made.back()->offset_rad = 80 * kDeg;
  for (int k = 0; k < 100; ++k) guard.update(in);
  EXPECT_FALSE(guard.lock_lost()) << "49.9 ms within is not enough";
  made.back()->offset_rad = 0;
  for (int k = 0; k < 500; ++k) guard.update(in);
  made.back()->offset_rad = 80 * kDeg;
  for (int k = 0; k < 20; ++k) guard.update(in);
  EXPECT_TRUE(guard.lock_lost());
}

TEST(LockGuard, OneThatNeverFindsTheRotorTripsOnItsSpeedAfter200Ms) {
  // Not armed (its angle never held), but its speed stays off the encoder's: a fresh observer
  // that never found the rotor while the shaft runs away. One converging inside 0.2 s does not.
  std::vector<Scripted*> made;
  LockGuard guard = make_guard(made);
  EstimatorInput in;
  in.encoder_omega_e_rad_s = 200.0;  // the scripted 100 rad/s is 100 off
  made.back()->offset_rad = 80 * kDeg;
  for (int k = 0; k < 1999; ++k) guard.update(in);
  EXPECT_FALSE(guard.lock_lost()) << "199.9 ms";
  made.back()->omega = 200.0;  // found the speed in time
  for (int k = 0; k < 10; ++k) guard.update(in);
  made.back()->omega = 100.0;
  for (int k = 0; k < 1999; ++k) guard.update(in);
  EXPECT_FALSE(guard.lock_lost()) << "the count starts again";
  guard.update(in);
  EXPECT_TRUE(guard.lock_lost()) << "0.2 s off the encoder's speed without ever holding";
}

TEST(LockGuard, ASpeedEstimateFarOffTheEncoderTripsItToo) {
  // An observer slipping by whole turns: its wrapped angle error need not stay beyond the guard.
  Fixture f;
  f.made.back()->omega = 139.0;  // 49 rad/s off the encoder's 90
  f.steps(1000, 10.0);
  EXPECT_FALSE(f.guard.lock_lost());
  f.made.back()->omega = 141.0;
  f.steps(19, 10.0);
  EXPECT_FALSE(f.guard.lock_lost());
  f.steps(1, 10.0);
  EXPECT_TRUE(f.guard.lock_lost());
}

TEST(LockGuard, ACurrentSurgeTripsItAtOnce) {
  Fixture f;
  f.in.ialpha_A = 3.0;
  f.in.ibeta_A = 3.9;  // |i| = 4.92 A
  f.steps(100, 0.0);
  EXPECT_FALSE(f.guard.lock_lost());
  f.in.ibeta_A = 4.1;  // 5.08 A
  f.steps(1, 0.0);
  EXPECT_TRUE(f.guard.lock_lost());
}

}  // namespace
}  // namespace synbench::emulator::firmware

namespace synbench::emulator::firmware {
namespace {

// An estimator that says it slipped (a low-speed handover that gave the angle back to the
// encoder above the take-over speed) is a lost rotor once the guard has armed, not before.
struct Slipping final : Estimator {
  bool slip = false;
  double theta = 0;
  void update(const EstimatorInput& in) override { theta = in.encoder_theta_e_rad; }
  EstimatorOutput output() const override {
    EstimatorOutput o;
    o.theta_e_rad = theta;
    o.omega_e_rad_s = 90.0;
    return o;
  }
  bool slipped() const override { return slip; }
};

TEST(LockGuard, AnEstimatorThatSlippedTripsItOnceArmed) {
  Slipping* inner = nullptr;
  LockGuard guard{[&inner] {
                    auto e = std::make_unique<Slipping>();
                    inner = e.get();
                    return e;
                  },
                  45 * kDeg, 50.0, 0.002, 5.0, 1e-4};
  EstimatorInput in;
  in.encoder_omega_e_rad_s = 90.0;
  inner->slip = true;
  for (int k = 0; k < 100; ++k) guard.update(in);
  EXPECT_FALSE(guard.lock_lost()) << "before it has held on its own";
  inner->slip = false;
  for (int k = 0; k < 500; ++k) guard.update(in);  // 50 ms: armed
  EXPECT_FALSE(guard.lock_lost());
  inner->slip = true;
  guard.update(in);
  EXPECT_TRUE(guard.lock_lost());
}

}  // namespace
}  // namespace synbench::emulator::firmware
