// Estimator selection, with the thesis configurations of physics.md Sec. 8.
#include "emulator/firmware/estimators/factory.hpp"

#include "drivers/error.hpp"
#include "emulator/firmware/estimators/ekf_basic.hpp"
#include "emulator/firmware/estimators/ekf_rs.hpp"
#include "emulator/firmware/estimators/hfi.hpp"

namespace synbench::emulator::firmware {

EstimatorChoice make_estimator(drivers::Estimator kind, const TwinConfig& config) {
  EstimatorChoice c;
  const double ts = config.step_s();
  switch (kind) {
    case drivers::Estimator::encoder:
      return c;
    case drivers::Estimator::ekf_basic: {
      EkfBasicParams p;
      p.ts_s = ts;
      c.estimator = std::make_unique<EkfBasic>(p);
      c.needs_mcidc = true;
      return c;
    }
    case drivers::Estimator::ekf_rs: {
      EkfRsParams p;
      p.ts_s = ts;
      c.estimator = std::make_unique<EkfRs>(p);
      c.needs_mcidc = true;
      return c;
    }
    case drivers::Estimator::hfi: {
      HfiParams p;
      p.ts_s = ts;
      c.estimator = std::make_unique<Hfi>(p);
      return c;
    }
    default:
      c.error = make_error_code(errc::not_supported);
      return c;
  }
}

}  // namespace synbench::emulator::firmware
