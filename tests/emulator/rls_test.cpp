// RLS stator identification and its PRBS excitation.
#include "emulator/firmware/estimators/rls.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "emulator/noise.hpp"

namespace synbench::emulator::firmware {
namespace {

TEST(Prbs5, IsAMaximalLengthSequenceOf31Bits) {
  Prbs5 p(0b10011);
  std::set<int> states;
  double sum = 0;
  for (int k = 0; k < 31; ++k) sum += p.advance(0.01, 0.01);
  EXPECT_EQ(sum, 1.0) << "16 ones and 15 minus ones per period";
  Prbs5 a(0b10011), b(0b10011);
  for (int k = 0; k < 31; ++k) a.advance(0.01, 0.01);
  for (int k = 0; k < 100; ++k) EXPECT_EQ(a.advance(0.01, 0.01), b.advance(0.01, 0.01)) << "period 31";
}

// A linear SynRM in a frame turning at w_e relative to the rotor (the estimated frame of a
// spinning machine), current-controlled by a PI on noisy samples with PRBS on both axes (Sec.
// 6.2.3): closed-loop data, as in the drive.
TEST(StatorRls, IdentifiesRsAndTheInductancesFromClosedLoopData) {
  const double rs = 9.68, ld = 0.5, lq = 0.12, ts = 1e-4, we = 150.0;
  const double psi_q0 = 0.1;  // affine flux offset of a saturated q axis
  const int every = 10;
  StatorRls rls(0.99, 1e5, every * ts);
  Prbs5 pd(0b10011), pq(0b01101);
  Noise noise(5);
  double id = 0, iq = 0, xi_d = 0, xi_q = 0;
  double id0 = 0, iq0 = 0, sum_id = 0, sum_iq = 0, sum_ud = 0, sum_uq = 0;
  for (int k = 1; k <= 60000; ++k) {
    const double idm = id + 0.0158 * noise.gauss(), iqm = iq + 0.0158 * noise.gauss();
    // PI current loops at 40 Hz holding 0.8 A, 1.2 A, plus PRBS.
    const double wc = 2 * M_PI * 40;
    xi_d += wc * rs * (0.8 - idm) * ts;
    xi_q += wc * rs * (1.2 - iqm) * ts;
    const double ud = wc * ld * (0.8 - idm) + xi_d + 20 * pd.advance(ts, 0.01);
    const double uq = wc * lq * (1.2 - iqm) + xi_q + 20 * pq.advance(ts, 0.01);
    // Rotor-frame voltage equations with the flux offset (Euler at ts / 10).
    for (int j = 0; j < 10; ++j) {
      const double h = ts / 10;
      const double did = (ud - rs * id + we * (lq * iq + psi_q0)) / ld;
      const double diq = (uq - rs * iq - we * ld * id) / lq;
      id += h * did;
      iq += h * diq;
    }
    sum_ud += ud;
    sum_uq += uq;
    if (k % every == 0) {
      const double idn = id + 0.0158 * noise.gauss(), iqn = iq + 0.0158 * noise.gauss();
      rls.update(idn - id0, iqn - iq0, sum_id / (every - 1), sum_iq / (every - 1), sum_ud / every,
                 sum_uq / every);
      id0 = idn;
      iq0 = iqn;
      sum_id = sum_iq = sum_ud = sum_uq = 0;
    } else {
      sum_id += idm;
      sum_iq += iqm;
    }
  }
  const auto e = rls.estimate();
  ASSERT_TRUE(e);
  EXPECT_NEAR(e->rs_ohm, rs, 0.1 * rs);
  EXPECT_NEAR(e->ld_H, ld, 0.1 * ld);
  EXPECT_NEAR(e->lq_H, lq, 0.1 * lq);
  // w J psi_off: the q offset's back-EMF on the d axis, nothing on q.
  EXPECT_NEAR(e->offset_g_V, -we * psi_q0, 0.1 * we * psi_q0);
  EXPECT_NEAR(e->offset_d_V, 0.0, 0.05 * we * psi_q0);
}

}  // namespace
}  // namespace synbench::emulator::firmware
