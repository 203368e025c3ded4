// The recording drives; see commanded_devices.hpp.
#include "app/commanded_devices.hpp"

namespace synbench::app {

CommandedDevices::CommandedDevices(drivers::BenchDevices inner)
    : inner_(inner), synrm_(inner.synrm, commanded_), load_(inner.load, commanded_) {}

drivers::BenchDevices CommandedDevices::devices() {
  drivers::BenchDevices d = inner_;
  if (d.synrm) d.synrm = &synrm_;
  if (d.load) d.load = &load_;
  return d;
}

}  // namespace synbench::app
