// Estimator selection.
#include "emulator/firmware/estimators/factory.hpp"

#include "drivers/error.hpp"

namespace synbench::emulator::firmware {

EstimatorChoice make_estimator(drivers::Estimator kind, const TwinConfig& /*config*/) {
  EstimatorChoice c;
  switch (kind) {
    case drivers::Estimator::encoder:
      return c;
    default:
      c.error = make_error_code(errc::not_supported);
      return c;
  }
}

}  // namespace synbench::emulator::firmware
