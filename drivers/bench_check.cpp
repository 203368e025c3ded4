// Cross-checks of a bench config and its profiles.
#include "drivers/bench_check.hpp"

#include <iterator>
#include <string>

namespace synbench::drivers {
namespace {

std::string place(const ProfileSignal& s) {
  std::string text = std::string(name(s.kind)) + " " + std::to_string(s.address);
  if (s.last_address() != s.address) text += "-" + std::to_string(s.last_address());
  return text + " at unit id " + std::to_string(s.unit_id);
}

const DeviceProfile& profile_of(const BenchProfiles& p, DeviceKind k) {
  return k == DeviceKind::synrm_drive ? p.synrm_drive : k == DeviceKind::load_drive ? p.load_drive : p.vfc_meter;
}

}  // namespace

std::optional<std::string> register_collision(const DeviceProfile& a, const DeviceProfile& b) {
  for (const ProfileSignal& sb : b.signals)
    for (const ProfileSignal& sa : a.signals)
      if (sa.unit_id == sb.unit_id && sa.kind == sb.kind && sa.address <= sb.last_address() &&
          sb.address <= sa.last_address())
        return "signal '" + sb.name + "' (" + place(sb) + ") overlaps " + std::string(name(a.kind)) + "'s signal '" +
               sa.name + "' (" + place(sa) + ")";
  return std::nullopt;
}

std::vector<FrozenBlindSpot> frozen_check_blind_spots(const BenchProfiles& profiles) {
  return frozen_blind_spots(telemetry_resolution(profiles.synrm_drive));
}

std::vector<ProfileError> check_bench(const BenchConfig& config, const BenchProfiles& profiles, bool one_endpoint) {
  std::vector<ProfileError> errors;
  for (std::size_t i = 0; i < kDeviceKinds.size(); ++i) {
    for (std::size_t j = i + 1; j < kDeviceKinds.size(); ++j) {
      const DeviceKind a = kDeviceKinds[i], b = kDeviceKinds[j];
      const std::string& link = config.device(b).link;
      if (!one_endpoint && config.device(a).link != link) continue;
      // One collision per pair of devices is enough to name the problem.
      if (const auto hit = register_collision(profile_of(profiles, a), profile_of(profiles, b)))
        errors.push_back({"/devices/" + std::string(name(b)) + "/profile",
                          *hit + (one_endpoint ? " on the one endpoint that serves them" : " on link '" + link + "'") +
                              ": give the devices different unit ids"});
    }
  }
  // A serial port opened twice: the second open fails or, worse, both read each other's replies.
  for (auto a = config.links.begin(); a != config.links.end(); ++a)
    for (auto b = std::next(a); b != config.links.end(); ++b)
      if (a->second.transport == LinkTransport::rtu && b->second.transport == LinkTransport::rtu &&
          a->second.rtu.device == b->second.rtu.device)
        errors.push_back({"/links/" + json_pointer_token(b->first) + "/device",
                          "'" + b->second.rtu.device + "' is also link '" + a->first +
                              "': devices on one line share one link"});
  return errors;
}

}  // namespace synbench::drivers
