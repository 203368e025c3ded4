// The active-flux rotor speed (emulator/firmware/estimators/active_flux_speed.hpp) on a machine
// written out here from the flux maps: u = Rs i + d psi / dt in the stationary frame. What the
// EEMF needs from it is a speed that does not move with the observer's angle error.
#include "emulator/firmware/estimators/active_flux_speed.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>

#include "emulator/flux_map.hpp"
#include "emulator/twin_config.hpp"

namespace synbench::emulator::firmware {
namespace {

constexpr double kTs = 1e-4;
constexpr double kPi = std::numbers::pi;
constexpr double kDeg = kPi / 180.0;

struct Run {
  double worst_speed_err_rad_s = 0;  // over the last `measure_s`
  double last_speed_rad_s = 0;
};

using Signal = std::function<double(double)>;
Signal constant(double v) {
  return [v](double) { return v; };
}

// The rotor turns at w(t) with the current (id, iq(t)) in its frame; the model's flux is the
// machine's, evaluated at the observer's angle th + offset(t).
Run run(const Signal& w_of_t, const Signal& offset_of_t, double id, const Signal& iq_of_t,
        double duration_s, double measure_s) {
  const TwinConfig cfg;
  const FluxAxis fd(cfg.synrm.flux_d), fq(cfg.synrm.flux_q);
  const double rs = cfg.synrm.rs_ohm;
  ActiveFluxSpeed s({kTs, 5.0, 0.015});
  s.align(0.0);  // it must find the speed itself
  const double psid = fd.psi(id);
  auto stator = [](double th, double d, double q, double& a, double& b) {
    a = std::cos(th) * d - std::sin(th) * q;
    b = std::sin(th) * d + std::cos(th) * q;
  };
  double th = 0, pa = 0, pb = 0;
  stator(th, psid, fq.psi(iq_of_t(0)), pa, pb);
  Run out;
  const long n = std::lround(duration_s / kTs), from = std::lround((duration_s - measure_s) / kTs);
  for (long k = 1; k <= n; ++k) {
    const double t = static_cast<double>(k) * kTs;
    const double w = w_of_t(t), iq = iq_of_t(t);
    const double psiq = fq.psi(iq), lq = fq.static_inductance_H(iq);
    th += w * kTs;
    double ia, ib, na, nb;
    stator(th, id, iq, ia, ib);
    stator(th, psid, psiq, na, nb);
    // The voltage over the period that just ended: the flux step plus the resistive drop.
    const double ua = (na - pa) / kTs + rs * ia, ub = (nb - pb) / kTs + rs * ib;
    pa = na;
    pb = nb;
    double ma, mb;
    stator(th + offset_of_t(t), psid, psiq, ma, mb);
    s.update(ua, ub, ia, ib, rs, ma, mb, lq);
    if (k >= from)
      out.worst_speed_err_rad_s = std::max(out.worst_speed_err_rad_s, std::fabs(s.omega_e_rad_s() - w));
  }
  out.last_speed_rad_s = s.omega_e_rad_s();
  return out;
}

const double kW500 = 500.0 / 60.0 * 2.0 * kPi * 2.0;  // 500 rpm, electrical

TEST(ActiveFluxSpeed, ReadsTheRotorSpeedWithTheObserversAngleWrongBy20Degrees) {
  // 2 N m at 60 deg. The start's offset (the flux begins at the model's, 20 deg off) turns the
  // flux circle off centre and fades at the blend's 5 rad/s; after 1.5 s it is gone.
  const auto r = run(constant(kW500), constant(20 * kDeg), 0.9, constant(1.57), 2.0, 0.5);
  EXPECT_LT(r.worst_speed_err_rad_s, 0.002 * kW500);
}

TEST(ActiveFluxSpeed, DoesNotMoveWithAnObserverErrorSwingingAt5Hz) {
  // The observer's angle error swings +-20 deg at 5 Hz, the unstable mode of the EEMF above the
  // MTPA angle: the observer's own speed is then off by up to 20 deg x 2 pi 5 Hz = 11 rad/s.
  const double own_err = 20 * kDeg * 2 * kPi * 5;
  const auto r = run(constant(kW500), [](double t) { return 20 * kDeg * std::sin(2 * kPi * 5 * t); },
                     0.9, constant(1.57), 1.0, 0.5);
  EXPECT_LT(r.worst_speed_err_rad_s, 0.1 * own_err) << "the blend leaks the observer's error";
}

TEST(ActiveFluxSpeed, FollowsASpeedRampWithTheFiltersLag) {
  // 500 -> 900 rpm in 1 s: alpha = 83.8 rad/s^2, lag alpha x 15 ms = 1.26 rad/s.
  const double alpha = (900.0 - 500.0) / 60.0 * 2.0 * kPi * 2.0;
  const auto r = run([=](double t) { return kW500 + alpha * std::min(t, 1.0); }, constant(0.0), 0.5,
                     constant(1.0), 1.0, 0.5);
  EXPECT_NEAR(r.worst_speed_err_rad_s, alpha * 0.015, 0.5);
}

TEST(ActiveFluxSpeed, IgnoresAQCurrentStep) {
  // A load step: i_q from 1.0 to 1.8 A in 10 ms at 1.5 s. The stator flux turns ahead by
  // atan(Psi_q / Psi_d), 6 deg here, in those 10 ms (10 rad/s); the active flux Psi - Lq i has
  // no q part and does not.
  const auto r = run(constant(kW500), constant(0.0), 0.9,
                     [](double t) { return 1.0 + 0.8 * std::clamp((t - 1.5) / 0.01, 0.0, 1.0); },
                     2.0, 0.6);
  EXPECT_LT(r.worst_speed_err_rad_s, 0.5);
}

}  // namespace
}  // namespace synbench::emulator::firmware
