// The low-speed handover (emulator/firmware/estimators/handover.hpp) around a scripted EEMF: it
// takes over above the minimum speed less the hysteresis, hands back below two hysteresis
// widths, and with the encoder as the fallback tells a slower shaft, and a dip of the speed
// estimate alone, from an estimate that fell away from the shaft's speed and angle (slipped).
#include "emulator/firmware/estimators/handover.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <optional>

namespace synbench::emulator::firmware {
namespace {

constexpr double kTs = 1e-4;
constexpr double kMin = 100.0, kHyst = 5.0;  // rad/s, electrical

constexpr double kSlipAngle = 0.785;  // rad

// Reports a scripted angle and speed; remembers the alignments it is given.
struct Scripted final : Estimator {
  double theta = 0, omega = 0, aligned_omega = 0;
  void update(const EstimatorInput&) override {}
  EstimatorOutput output() const override {
    EstimatorOutput o;
    o.theta_e_rad = theta;
    o.omega_e_rad_s = omega;
    return o;
  }
  void align(double theta_e_rad, double omega_e_rad_s) override {
    aligned_omega = omega_e_rad_s;
    theta = theta_e_rad;
    omega = omega_e_rad_s;
  }
};

struct Fixture {
  Scripted* main = nullptr;
  std::unique_ptr<LowSpeedHandover> h;
  EstimatorInput in;
  Fixture() {
    auto m = std::make_unique<Scripted>();
    main = m.get();
    h = std::make_unique<LowSpeedHandover>(std::move(m), nullptr, kMin, kHyst, kSlipAngle, kTs);
  }
  // 0.1 s with the shaft at `shaft` and the EEMF's estimate at `estimate`, its angle `off_rad`
  // from the encoder's (once it is the source). The encoder's angle advances at the shaft's
  // speed; the hand-back's period is recorded.
  void run(double shaft, double estimate, double off_rad = 0.0) {
    in.encoder_omega_e_rad_s = shaft;
    for (int k = 0; k < 1000; ++k) {
      in.encoder_theta_e_rad = wrap_pi(in.encoder_theta_e_rad + shaft * kTs);
      if (h->main_active()) {
        main->omega = estimate;
        main->theta = wrap_pi(in.encoder_theta_e_rad + off_rad);
      }
      const bool was_active = h->main_active();
      h->update(in);
      if (was_active && !h->main_active()) handed_back = {in.encoder_theta_e_rad, h->output()};
    }
  }
  struct HandBack {
    double encoder_theta_rad;
    EstimatorOutput out;
  };
  std::optional<HandBack> handed_back;
};

TEST(LowSpeedHandover, TakesOverAboveTheMinimumLessTheHysteresis) {
  Fixture f;
  f.run(90.0, 90.0);
  EXPECT_TRUE(f.h->on_fallback());
  EXPECT_NEAR(f.main->aligned_omega, 90.0, 1e-9) << "kept aligned to the encoder";
  f.run(97.0, 97.0);
  EXPECT_FALSE(f.h->on_fallback());
  EXPECT_FALSE(f.h->slipped());
}

TEST(LowSpeedHandover, ASlowerShaftIsNoSlip) {
  Fixture f;
  f.run(100.0, 100.0);
  ASSERT_FALSE(f.h->on_fallback());
  f.run(85.0, 85.0);  // the shaft below min - 2 hyst, the estimate with it
  EXPECT_TRUE(f.h->on_fallback());
  EXPECT_FALSE(f.h->slipped());
}

TEST(LowSpeedHandover, AnEstimateFallingAwayFromTheShaftSlipped) {
  Fixture f;
  f.run(100.0, 100.0);
  ASSERT_FALSE(f.h->on_fallback());
  f.run(100.0, 85.0, 1.0);  // the shaft holds; the estimate falls below min - 2 hyst, 57 deg off
  // Handed back, and taken over again aligned to the encoder at once (the shaft is above the
  // take-over speed): without the flag nothing would show but a jump of the angle.
  EXPECT_TRUE(f.handed_back);
  EXPECT_TRUE(f.h->slipped());
}

TEST(LowSpeedHandover, ASpeedEstimateDippingWithTheAngleHeldIsNoSlip) {
  // At 500 rpm the EEMF-RLS observer's speed dips under the hand-back speed while its angle stays
  // within its in-lock spread (6 to 12 deg); a hand-back then, not a lost rotor.
  Fixture f;
  f.run(100.0, 100.0);
  ASSERT_FALSE(f.h->on_fallback());
  f.run(100.0, 85.0, -0.2);
  EXPECT_TRUE(f.handed_back);
  EXPECT_FALSE(f.h->slipped());
  f.run(100.0, 100.0);
  EXPECT_FALSE(f.h->on_fallback()) << "taken over again: the shaft is above the take-over speed";
}

TEST(LowSpeedHandover, TheHandBackPeriodAlreadyGivesTheEncodersAngle) {
  // It gave, for that one period, the angle the encoder had when the observer took over (about
  // 0.13 s and 13 rad earlier here): on the thesis grid's 500 rpm points one period tens of
  // degrees off, which the window's position error counted as the observer out of lock.
  Fixture f;
  f.run(90.0, 90.0);
  f.run(100.0, 100.0);
  ASSERT_FALSE(f.h->on_fallback());
  f.run(88.0, 88.0);
  ASSERT_TRUE(f.handed_back);
  EXPECT_DOUBLE_EQ(f.handed_back->out.theta_e_rad, f.handed_back->encoder_theta_rad);
  EXPECT_DOUBLE_EQ(f.handed_back->out.omega_e_rad_s, 88.0);
}

}  // namespace
}  // namespace synbench::emulator::firmware
