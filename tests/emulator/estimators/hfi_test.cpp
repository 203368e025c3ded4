// HFI's initial position detection: after a start the estimator asks the drive for no torque
// current for align_s, and not when another source hands it the angle.
#include "emulator/firmware/estimators/hfi.hpp"

#include <gtest/gtest.h>

namespace synbench::emulator::firmware {
namespace {

TEST(Hfi, AlignsForItsTimeAfterAStartButNotWhenHandedTheAngle) {
  HfiParams p;
  p.align_s = 0.1;
  Hfi h(p);
  EstimatorInput in;
  in.ts_s = p.ts_s;
  int aligning = 0;
  for (int k = 0; k < 2000; ++k) {
    aligning += h.aligning() ? 1 : 0;
    h.update(in);
  }
  EXPECT_EQ(aligning, 1000) << "0.1 s at 10 kHz";
  Hfi handed(p);
  EXPECT_TRUE(handed.aligning());
  handed.align(1.0, 50.0);
  EXPECT_FALSE(handed.aligning());
  p.align_s = 0;
  EXPECT_FALSE(Hfi(p).aligning());
}

}  // namespace
}  // namespace synbench::emulator::firmware
