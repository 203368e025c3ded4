// What a bench config's parts cannot see one at a time: devices whose registers collide on one
// link (same unit id, same table, overlapping addresses: the bench would read one device's
// register as the other's) and two links on one serial port. `synbench bench check` reports
// these after the config and its profiles have parsed, and which telemetry values the
// supervisor's frozen-value check cannot watch; `synbench emulate --bench`, which serves
// every device on each of its endpoints, checks as if all devices shared one link.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "drivers/bench_config.hpp"
#include "drivers/frozen_watch.hpp"

namespace synbench::drivers {

// The first signal of `b` whose registers overlap one of `a`'s (same unit id and table), in
// words naming both signals ("signal 'enable' (coil 0 at unit id 1) overlaps synrm_drive's
// signal 'enable' (coil 0 at unit id 1)"); nullopt when they can share a link.
std::optional<std::string> register_collision(const DeviceProfile& a, const DeviceProfile& b);

// The SynRM drive's values the supervisor's frozen-telemetry check cannot watch with these
// profiles (drivers/frozen_watch.hpp): no problem, but what the bench will not see.
std::vector<FrozenBlindSpot> frozen_check_blind_spots(const BenchProfiles& profiles);

// Each problem at the pointer of the later device's profile ("/devices/load_drive/profile") or
// of the later link ("/links/b/device"), naming both sides.
std::vector<ProfileError> check_bench(const BenchConfig& config, const BenchProfiles& profiles,
                                      bool one_endpoint = false);

}  // namespace synbench::drivers
